// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world node (docs/architecture.md §1.3): one World on its schedule. Each step takes the newest report from the
// world link, steps the world, publishes the frame and the loop statistics, and logs a row. Real time: its own clock at
// the world rate. Lockstep: a step per turn the link gives (shared memory), or whenever the in-process link calls
// step_world().
//
// Owns its World, log and statistics; its summary is the world half of summary.json (docs/architecture.md §4).

#include "common/link/inproc/inproc_world_link.h"
#include "common/contract/world_view.h"
#include "common/link/world_link.h"
#include "common/runtime/loop_stats.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"
#include "world_manager/world_log.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <vector>
#include <memory>
#include <optional>
#include <string>

namespace impetus {

struct WorldNodeOptions {
  std::string scene_path;
  // A scene built in memory (its JSON text): when not empty it is the scene, and scene_path only names it in messages
  // and the summary.
  std::string scene_text;
  std::optional<double> rate_hz;  // default: the scene's physics.world_rate_hz
  std::optional<int> substeps;    // default: the scene's physics.substeps
  // The rigid-body engine by its registry name (engine/engine_registry.h); default: the scene's physics.engine. The
  // engine reads its own block of the scene, if the scene has one.
  std::optional<std::string> engine;
  Coupling coupling = Coupling::impulse;
  bool passivity = false;  // the passivity layer on the impulse port (WorldOptions::passivity)
  ClockMode clock = ClockMode::realtime;
  std::uint64_t phase_ticks = 0;
  double duration_s = 0.0;  // 0: until stopped
  std::string log_path;     // "" : no log
  double haptic_rate_hz = limits::kDefaultHapticRate_Hz;  // lockstep: the world period must be a whole number of haptic ticks
  std::uint64_t world_session = 0;  // 0: a fresh new_session_id()
};

class WorldNode final : public WorldStepper {
 public:
  // Loads the scene (SceneError names the file and field), builds the world, opens the log. Throws
  // std::invalid_argument for a lockstep period that is not a whole number of haptic ticks.
  explicit WorldNode(const WorldNodeOptions& options);

  // What the link tells haptic nodes at attach.
  WorldLinkInfo link_info() const;
  // The link to serve; must be set before run() or the first step, and outlive the node.
  void connect(WorldLinkServer& link) { link_ = &link; }
  // Viewers (optional): publishes the scene now and a snapshot after every step. Must outlive the node.
  void connect_view(WorldViewPublisher& view);

  // Runs until the duration, a stop request, or (lockstep) the end of the session. Returns the exit status.
  int run();
  // One world step (the in-process link's lockstep turn).
  void step_world() override;

  // Start-up warnings a user should see: objects too light for the coupling at this rate, objects placed inside each
  // other or the floor. Also in the summary ("world": {"warnings": [...]}).
  std::vector<std::string> warnings() const;
  // The world half of summary.json: objects, world statistics, config.
  nlohmann::json summary() const;
  const World& world() const { return world_; }

 private:
  nlohmann::json escaped_names() const;
  std::size_t asleep_count() const;  // dynamic objects asleep now
  void publish_stats(const class RealtimeClock* clock);

  WorldNodeOptions options_;
  Scene scene_;
  World world_;
  WorldLinkServer* link_ = nullptr;
  WorldViewPublisher* view_ = nullptr;
  std::unique_ptr<WorldSnapshot> snapshot_;  // ~120 KB at full capacity: allocated once, in connect_view
  std::optional<WorldLog> log_;  // written by its own thread; reports a failed write when it happens
  // Per endpoint slot of the link: its newest report, and when it last changed (staleness).
  struct SlotReport {
    HapticReport report{};
    bool have = false;
    std::uint64_t tick = 0;
    std::uint64_t session = 0;
    std::int64_t fresh_ns = 0;
  };
  std::vector<SlotReport> reports_;  // kMaxEndpoints (~7 KB each: on the heap)
  HapticReport incoming_{};
  std::array<const HapticReport*, kMaxEndpoints> report_of_slot_{};
  // Steps × endpoints whose finger the world dropped because their reports stopped arriving (real time).
  std::uint64_t stale_finger_steps_ = 0;
  std::size_t escapes_reported_ = 0;  // world_.escaped() entries already announced on stderr
  LoopStats stats_;
  LatencyHistogram step_cpu_ns_;  // CPU time of World::step (coupling + engine + features), per step
};

}  // namespace impetus
