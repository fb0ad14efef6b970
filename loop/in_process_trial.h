// SPDX-License-Identifier: Apache-2.0
#pragma once
// One trial with the world, haptic and device nodes in this process over the in-process links (docs/architecture.md
// §1.3, §2): the same nodes the three daemons run, under the lockstep schedule, on the calling thread. Bitwise the same
// outcome as the three processes in lockstep (`scripts/run.sh --clock lockstep`), without starting any process.
//
// This is the library's entry point for embedding Impetus (Impetus::loop): load a scene file, pick a trajectory and a
// coupling, run, read the summary.

#include "common/contract/frames.h"
#include "spidar_sim/trajectory.h"

#include <nlohmann/json.hpp>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace impetus {

// The longest link delay a trial takes: a second each way is beyond any network a haptic user would put up with, and
// keeps the delay line's reports (one per tick) to a thousand per finger at 1 kHz.
inline constexpr double kMaxLinkDelay_s = 1.0;
// Loss beyond half the packets, or runs of more than a thousand, is a link that is down, not a lossy one.
inline constexpr double kMaxLinkLoss = 0.5;
inline constexpr double kMaxLossBurst = 1000.0;

struct InProcessTrialOptions {
  std::string scene_path;  // a scene file (world_manager/scene.h)
  // Or a scene built in memory, as JSON text: when not empty it is the scene, and scene_path only names it in
  // messages and the summary.
  std::string scene_text;
  std::string trajectory;  // a trajectory CSV file or a built-in spec, as spidar_sim --trajectory takes
  // Or the fingers themselves, trajectories already made (from arrays): when not empty, trajectory and fingers must be.
  std::vector<NamedFinger> finger_paths;
  // Or a several-finger device: "NAME=TRAJECTORY" per finger, as spidar_sim --finger takes (then `trajectory` must be
  // empty). Finger k is endpoint k of the world; its logs are haptic.endpointK.csv and device.endpointK.csv.
  std::vector<std::string> fingers;
  // Other users on the same world, each a haptic controller of its own with its fingers ("NAME=TRAJECTORY" each):
  // they follow the first controller's lockstep ticks (docs/architecture.md §3). User u's logs are userU.haptic.csv and
  // userU.device.csv (u = 1, 2, ...), its summary under "followers".
  std::vector<std::vector<std::string>> followers;
  Coupling coupling = Coupling::impulse;
  bool passivity = false;  // world_manager --passivity
  std::uint64_t phase_ticks = 0;  // lockstep phase of the world clock, in haptic ticks (< one world period)
  // Each has the range of the daemon flag it mirrors (common/contract/limits.h) and the same default.
  std::optional<double> world_rate_hz;  // world_manager --rate; default: the scene's physics.world_rate_hz
  std::optional<int> substeps;          // world_manager --substeps; default: the scene's physics.substeps
  std::optional<std::string> engine;    // world_manager --engine; default: the scene's physics.engine
  double stiffness_Npm = std::numeric_limits<double>::quiet_NaN();  // haptic_controller --stiffness; NaN: the scene's
  double damping_Nspm = std::numeric_limits<double>::quiet_NaN();   // haptic_controller --damping; NaN: the scene's
  double duration_s = 0.0;  // haptic_controller --duration: the longest trial in seconds; 0: the whole trajectory
  // One-way delay of the world link, the same both ways, in seconds: 0 (none) to kMaxLinkDelay_s, rounded to the
  // nearest whole haptic tick (a delay below half a tick is none). Frames reach the haptic side and reports the world
  // that many ticks late (common/link/inproc/inproc_world_link.h says exactly when); summary.json's "link" records
  // it. For latency experiments: the daemons' links (shared memory, DDS) have no delay line, so no flag mirrors it.
  double link_delay_s = 0.0;
  // Loss on the world link, each direction alike (common/link/link_loss.h): the fraction of frames and of
  // reports lost, 0 to kMaxLinkLoss, and the mean run of consecutive losses in packets, 1 to kMaxLossBurst (1:
  // independent losses). Seeded, so a lossy trial is repeatable; summary.json's "link" counts what was lost.
  double link_loss = 0.0;
  double link_loss_burst = 1.0;
  // world.csv, haptic.csv and device.csv are written here when it is not empty; nothing is written otherwise.
  std::filesystem::path out_dir;
  // Set by another thread to end the trial between two ticks (Ctrl-C in Python); the summary then covers what ran.
  // Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

// Runs the trial to the end of its trajectory; returns the world, haptic and device halves of summary.json merged,
// and "link": {"delay_s", "delay_ticks", "dropped"} (the delay applied, in seconds and whole ticks, and entries its
// delay line dropped: always 0 unless a node stopped taking its frames).
// Thread-safe: concurrent calls run one after another (ODE's state is process-wide); for trials in parallel use
// processes. Nothing else in the process may step an ODE world meanwhile.
// Throws std::invalid_argument for an option out of its range (naming the option, the value and the range) and
// std::runtime_error (SceneError, TrajectoryError, ...) for a bad file, naming the file and the field.
nlohmann::json run_in_process_trial(const InProcessTrialOptions& options);

}  // namespace impetus
