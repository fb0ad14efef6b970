// SPDX-License-Identifier: Apache-2.0
#pragma once
// The haptic node (docs/architecture.md §1.3): the 1 kHz servo on its schedule. Each tick: the finger from the device,
// the world's newest frame from the world link, HapticServo::tick, the force back to the device, the report to the
// world, a log row into the real-time ring. Real time: its own clock, and a supervisor thread that does what the servo
// loop must not (re-attaching to a restarted world). Lockstep: the master; the device advances once per tick and the
// world steps at tick i·n + phase (common/runtime/lockstep_schedule.h).
//
// Owns the servo, its log and statistics; its summary is the haptic half of summary.json (docs/architecture.md §4).

#include "common/contract/limits.h"
#include "common/link/inproc/inproc_world_link.h"
#include "common/link/world_link.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/log_paths.h"
#include "common/runtime/loop_stats.h"
#include "common/runtime/process.h"
#include "common/runtime/rt_log.h"
#include "common/contract/tool.h"
#include "haptic_controller/device/haptic_device.h"
#include "haptic_controller/servo.h"
#include "haptic_controller/tool/tool_servo.h"

#include <nlohmann/json.hpp>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace impetus {

struct HapticNodeOptions {
  double rate_hz = limits::kDefaultHapticRate_Hz;
  double stiffness_Npm = std::numeric_limits<double>::quiet_NaN();  // NaN: the scene's (servo.h)
  double damping_Nspm = std::numeric_limits<double>::quiet_NaN();
  ClockMode clock = ClockMode::realtime;
  double duration_s = 0.0;  // 0: until stopped (lockstep: until the device leaves, or stopped)
  std::string log_path;     // "": no log
  bool realtime_priority = true;
  std::uint64_t haptic_session = 1;  // nonzero; the nodes' mains pass new_session_id() (common/runtime/process.h)
  // Lockstep master: other controllers (users) to wait for before the first tick; they then follow its ticks.
  std::uint32_t followers = 0;
  // Besides the process's stop request (g_stop_requested): a flag its owner sets to end the trial between two ticks
  // (an in-process trial interrupted from Python). Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
  // A tool in the hand (docs/tool.md): the endpoint is the grip of an oriented device (HapticDevice::oriented), served
  // by a tool servo (tool/tool_servo.h) instead of the point finger's. The coupling's limits are lowered to the
  // device's where they exceed them.
  std::optional<ToolShape> tool;
  ToolCoupling tool_coupling;
};

// One row of the haptic log (the ring holds these; formatted by the drain thread).
struct HapticLogRow {
  std::uint64_t tick;
  double time_s;
  Vec3 finger_m, proxy_m, force_N;
  Vec3 object_impulse_Ns;  // sum of the cumulative totals over all objects
  Vec3 static_impulse_Ns;  // cumulative share into static geometry
  double interpolation_weight;
  std::int64_t lateness_ns;
  std::int32_t active_planes;
  std::uint32_t flags;  // bit 0 finger valid, 1 saturated, 2 fault, 3 world stale, 4 sticking
};

// One row of a tool's pose log (haptic.tool.csv beside haptic.csv): the grip's and the proxy's poses, which the
// haptic log's point columns cannot hold, and the wrench on the grip.
struct ToolLogRow {
  std::uint64_t tick;
  double time_s;
  Vec3 grip_m;
  std::array<double, 4> grip_wxyz;  // unit quaternion, grip → world
  Vec3 proxy_m;
  std::array<double, 4> proxy_wxyz;
  Vec3 force_N;    // on the grip
  Vec3 torque_Nm;  // on the grip, about its centre
  std::int32_t active_contacts;
  std::uint32_t flags;  // bit 0 grip valid, 1 saturated, 3 world stale (the haptic log's bits)
};

// The running total of the reaction a report's endpoint has given all objects together (N·s): the sum of its
// entries' totals, as the haptic log's object_impulse columns record it.
inline Vec3 object_impulse_total_Ns(const HapticReport& report) {
  Vec3 total{};
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    for (int a = 0; a < 3; ++a) total[a] += report.entries[k].impulse_Ns[a];
  }
  return total;
}

// A haptic node serves one endpoint per finger of its device (HapticDevice::finger_count()): a servo each, ticked in
// finger order every tick, their forces commanded to the device together. With a tool (HapticNodeOptions::tool) its
// one endpoint is an oriented device's grip, served by a tool servo: the grip's pose in, force and torque out.
class HapticNode final : public FollowerStepper {
 public:
  // The link and the device must outlive the node. Throws std::invalid_argument for a lockstep world period that is
  // not a whole number of ticks or a link whose endpoints do not match the device's fingers, std::runtime_error if a
  // log cannot be opened.
  HapticNode(const HapticNodeOptions& options, WorldLinkClient& world, HapticDevice& device);

  // Whether the trial ended at --duration (a trajectory longer than it was cut; the summary's "duration_reached").
  bool duration_reached() const { return duration_reached_; }
  // Throws std::invalid_argument also for a tool without an oriented one-grip device, or an oriented device without a
  // tool. Runs until the duration, a stop request, or (lockstep) no device. Returns the exit status.
  int run();

  // Lockstep, driven from outside (several nodes in one process, the first the master): tick `t` of this node, with
  // the world step due at it if this node's link is the master. False when the device has left or a stop was
  // requested: the run is over; then finish_lockstep() ends it.
  bool lockstep_tick(std::uint64_t t);
  void finish_lockstep();
  // After the last tick (run() calls it): the final statistics, the logs flushed and closed. Returns the exit status
  // run() would (1 for a trial cut short or a failed log write).
  int close();
  // A follower's tick `t` (another controller is the lockstep master): the frames the world published after the
  // master's tick t−1, taken at time (t−1)·T as the master took them, then tick t. False once its device has left or
  // a stop was requested (nothing was ticked).
  bool follow_tick(std::uint64_t t) override;

  // The haptic half of summary.json; per endpoint under "endpoints".
  nlohmann::json summary() const;
  const HapticServo& servo(EndpointId endpoint = 0) const { return endpoints_[endpoint]->servo; }
  // The tool servo of a node with a tool (nullptr without).
  const ToolServo* tool_servo() const { return endpoints_[0]->tool.get(); }
  std::uint32_t endpoint_count() const { return static_cast<std::uint32_t>(endpoints_.size()); }

 private:
  bool stop_requested() const {
    return g_stop_requested.load() || (options_.stop != nullptr && options_.stop->load());
  }
  // One finger's servo and what the node records about it.
  struct Endpoint {
    Endpoint(const ServoOptions& options, std::uint64_t session, EndpointId id) : servo(options, session, id) {}
    HapticServo servo;
    std::unique_ptr<ToolServo> tool;  // serves the endpoint instead of `servo` when the node has a tool
    std::optional<RtLog<HapticLogRow>> log;
    std::optional<RtLog<ToolLogRow>> tool_log;  // a tool endpoint's poses
    double max_force_N = 0.0;
    double max_torque_Nm = 0.0;  // a tool's
    double stiffness_Npm = 0.0;  // k_p and k_d of the last tick that rendered a force
    double damping_Nspm = 0.0;
  };

  void tick(std::uint64_t tick, double now_s, double dt_s, std::int64_t lateness_ns);
  void log_tick(Endpoint& endpoint, std::uint64_t tick, double now_s, const TickResult& result, bool saturated,
                std::int64_t lateness_ns);
  // A tool endpoint's tick: the grip's sample (nullptr: none) → the tool servo → the command.
  void tick_tool(Endpoint& endpoint, const FingerSample* grip, double now_s, double dt_s, FingerCommand& command);
  void log_tool_tick(Endpoint& endpoint, std::uint64_t tick, double now_s, bool saturated, std::int64_t lateness_ns);
  static const HapticReport& report_of(const Endpoint& endpoint);
  static std::uint64_t ticks_of(const Endpoint& endpoint);
  static std::uint64_t faults_of(const Endpoint& endpoint);
  void receive_frames(double now_s);
  void run_lockstep();
  void run_follower();
  void run_realtime();
  void publish_stats(const class RealtimeClock* clock);
  std::uint64_t max_ticks() const;
  nlohmann::json endpoint_summary(const Endpoint& endpoint) const;

  HapticNodeOptions options_;
  bool duration_reached_ = false;  // the trial ended at options_.duration_s, not because the device left
  double period_s_;
  WorldLinkClient& world_;
  bool cut_short_ = false;  // lockstep: the world or the device went away mid-trial
  bool world_lost_ = false;
  HapticDevice& device_;
  std::vector<std::unique_ptr<Endpoint>> endpoints_;
  std::vector<HapticServo*> servos_;  // endpoints_[k]->servo, for exchange_pushes
  std::array<FingerCommand, kMaxFingers> commands_{};
  PlaneFrame frame_buffer_{};
  std::optional<LockstepSchedule> schedule_;  // lockstep only
  LatencyHistogram clock_stats_;
  LatencyHistogram tick_cpu_ns_;  // CPU time of HapticServo::tick, on every 64th tick
  std::uint64_t skipped_periods_ = 0;
};

}  // namespace impetus
