// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device node (docs/architecture.md §1.3): a simulated device on the device port: the 4-string SPIDAR and its
// finger (DeviceSim), or the 8-string grip SPIDAR and its hand (GripDeviceSim, grip_device_sim.h). Each tick
// takes the newest commanded tensions (minimum tension before the first command), advances the simulation and publishes
// the encoder counts. Lockstep: one tick per turn the host gives (shared memory), or per in-process step_device() call;
// when the trajectory ends the node detaches. Real time: its own 1 kHz clock until the trajectory ends; the trajectory
// holds at its start until the haptic controller says it renders a world (kCommandWorldPresent), at most the world
// wait, so a script is not played before there is anything to touch (the processes start in any order).
//
// Owns the simulation's log and statistics. `Sim` provides: kStrings; LogRow, log_header(), format_log_row(),
// log_row(); tick(tensions, dt_s) → the DeviceState to publish; tension_min_N(); hold_trajectory(dt_s); finished();
// time_s(); kMaxTick_s; and summary_fields(), its part of the device summary.

#include "common/runtime/rt_log.h"
#include "common/link/device_port.h"
#include "common/link/inproc/inproc_device_port.h"
#include "spidar_sim/command_watchdog.h"
#include "spidar_sim/device_sim.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <optional>
#include <string>

namespace impetus {

class GripDeviceSim;

template <class Sim>
class DeviceNodeOf final : public DeviceStepper {
 public:
  // `sim` and `port` must outlive the node. Throws std::runtime_error if the log cannot be opened.
  DeviceNodeOf(Sim& sim, DevicePortClient& port, const std::string& log_path, std::uint64_t device_session);

  // Runs until the trajectory ends, the host ends the session or dies, or a stop is requested. Returns the exit
  // status.
  int run();
  // Real time: the longest the trajectory holds at its start for a world, s (0: play at once). Default kWorldWait_s.
  void set_world_wait(double max_s) { world_wait_s_ = max_s; }
  // A world frame reaches a controller within a second of both starting; ten is a controller with no world coming.
  static constexpr double kWorldWait_s = 10.0;

  // One lockstep tick (the in-process port's turn); false once the trajectory has ended and the node detached.
  bool step_device() override;

  // The device's part of summary.json: ticks, and the finger, hand and device parameters the trial ran with.
  nlohmann::json summary() const;

  std::uint64_t ticks() const { return ticks_; }
  const Sim& sim() const { return sim_; }

 private:
  void tick(double dt_s);
  void publish_stats(const class RealtimeClock* clock);

  Sim& sim_;
  DevicePortClient& port_;
  std::uint64_t session_;
  CommandWatchdog watchdog_;             // a stalled servo's last command is not applied for long
  // Rows leave the tick as copies and are formatted and written by the log's own thread (rt_log.h): lockstep waits
  // for room (a complete log), real time drops and counts.
  std::optional<RtLog<typename Sim::LogRow>> log_;
  bool cut_short_ = false;               // lockstep: the haptic controller died before the trajectory ended
  double world_wait_s_ = kWorldWait_s;
  bool holding_for_world_ = false;       // real time: the trajectory holds at its start (set by run())
  bool world_seen_ = false;              // a command said the controller renders a world
  double held_s_ = 0.0;                  // device time the trajectory held for a world
  std::uint64_t ticks_ = 0;
};

using DeviceNode = DeviceNodeOf<DeviceSim>;      // a finger's
using GripDeviceNode = DeviceNodeOf<GripDeviceSim>;  // the grip's

// The device half of summary.json for a device of one or several fingers (node k plays fingers[k]): finger 0's
// summary and, when there are several, each finger's under "device"."fingers" with its name and trajectory.
nlohmann::json fingers_summary(std::span<const std::unique_ptr<DeviceNode>> nodes,
                               std::span<const NamedFinger> fingers);

}  // namespace impetus
