// SPDX-License-Identifier: Apache-2.0
#pragma once
// One simulated device session: the SPIDAR hardware, the finger and the scripted target, advanced one device tick at a
// time (docs/architecture.md §1.2 "One device tick"). main.cpp wires it to the device port and the clock; tests drive
// it directly.
//
// Contract of tick(): the commanded tensions are held for dt_s (zero-order hold, like a motor amplifier's setpoint);
// within the tick the finger is integrated in sub-steps, re-evaluating the target and the string directions at each;
// the returned state carries the encoder counts at the end of the tick. Time starts at 0 with the finger at rest on
// the trajectory's start and the motors at the minimum tension. No allocation after construction.

#include "common/spidar/geometry.h"
#include "common/contract/frames.h"
#include "spidar_sim/trajectory.h"
#include "common/contract/vec3.h"
#include "common/hand/finger.h"
#include "spidar_sim/spidar_hardware.h"

#include <nlohmann/json.hpp>

#include <array>
#include <ostream>

namespace impetus {

// One row of the device log (docs/architecture.md §4 "Logs"): copied out of a tick, formatted by another thread
// (rt_log.h).
struct DeviceLogRow {
  double time_s;
  Vec3 target_m, finger_m, finger_velocity_mps, force_N;
  std::array<double, kStringCount> tension_N;
  std::array<std::int64_t, kStringCount> encoder_counts;
};

// Why `trajectory` cannot be played on a device of `geometry`, or "" if it can: a target outside the frame's cube, where
// no string tension holds the finger (the device would only saturate). Names the time and the point.
std::string trajectory_problem(const Trajectory& trajectory, const SpidarGeometry& geometry);

class DeviceSim {
 public:
  // Throws std::invalid_argument (from the parts) if the geometry or parameters are unusable, and TrajectoryError if
  // the trajectory leaves the device's frame (where the strings cannot hold the finger: trajectory_problem).
  DeviceSim(const SpidarGeometry& geometry, HardwareParams hardware, FingerParams finger, Trajectory trajectory);

  // Advances one device tick of dt_s (finite, > 0 and at most kMaxTick_s; else std::invalid_argument) and returns the
  // encoder counts at its end with `tick` incremented (the first call returns tick 1). The caller sets
  // device_session and seals the frame before publishing it.
  const DeviceState& tick(const std::array<double, kStringCount>& commanded_tension_N, double dt_s);

  // Closed loop (loop/simulation.h): the caller moves the target instead of the trajectory. steer() says where the
  // target is at the end of the next tick; over that tick it moves in a straight line from where it is now (a chord,
  // as the trajectory's is over a sub-step), then holds there until steered again. From the first steer() on the
  // trajectory is no longer played and the session never finishes: its owner ends it. A caller that steers to the
  // trajectory's own points at the tick ends, position_at(time_s() + dt_s), gets bitwise the trajectory's run when a
  // tick is one sub-step (the default finger and motors without lag). `target_m` must be finite (not checked here).
  void steer(const Vec3& target_m);
  // A force (N) the hand adds on the finger, on top of its impedance about the target, held until set again: a
  // controller that pushes instead of aiming. Steers the target where it is, as steer() does. Finite (not checked).
  void set_hand_force(const Vec3& force_N);
  bool steered() const { return steered_; }
  // Holds the trajectory for the next tick of dt_s: its clock stands still, the target stays where the trajectory is
  // now (its start, before it began), and the finger rests there under the device's forces. A real-time device
  // waiting for a world to touch calls it before each tick it waits (device_node.h).
  void hold_trajectory(double dt_s) { trajectory_start_s_ += dt_s; }

  // A realtime hiccup longer than this is a bug upstream, not a tick: the sub-step count would explode.
  static constexpr double kMaxTick_s = 1.0;
  static constexpr int kStrings = kStringCount;
  using LogRow = DeviceLogRow;

  double tension_min_N() const { return hardware_.geometry().tension_min_N; }
  // The finger's, hand's and device's parameters, for the device summary (device_node.h).
  nlohmann::json summary_fields() const;

  const DeviceState& state() const { return state_; }
  double time_s() const { return time_s_; }
  // Where the trajectory's clock is: session time less the time it was held.
  double trajectory_time_s() const { return time_s_ - trajectory_start_s_; }
  Vec3 target_m() const { return steered_ ? target_now_m_ : trajectory_.position_at(trajectory_time_s()); }
  const Vec3& hand_force_N() const { return hand_force_N_; }
  Vec3 finger_m() const { return to_vec3(finger_.position_m()); }
  Vec3 finger_velocity_mps() const { return to_vec3(finger_.velocity_mps()); }
  // Net string force on the finger at the end of the last tick (N): Σ t_i·u_i.
  Vec3 device_force_N() const { return to_vec3(hardware_.force_on_finger(finger_.position_m())); }
  const std::array<double, kStringCount>& tensions_N() const { return hardware_.tensions_N(); }
  const std::array<std::int64_t, kStringCount>& encoder_counts() const { return counts_; }
  // True once the session time reaches the end of the trajectory (the target then holds still).
  bool finished() const { return !steered_ && trajectory_time_s() >= trajectory_.duration_s(); }

  const Trajectory& trajectory() const { return trajectory_; }
  const SpidarHardware& hardware() const { return hardware_; }
  const Finger& finger() const { return finger_; }

  // Log (docs/architecture.md §4 "Logs"): one header, then one row per tick with time, target, finger position and
  // velocity, device force, applied tensions and encoder counts.
  static const char* log_header();  // the column names, without the line's end
  DeviceLogRow log_row() const;      // this tick's row; no allocation
  static void format_log_row(std::ostream& out, const DeviceLogRow& row);
  static void write_log_header(std::ostream& out) { out << log_header() << '\n'; }
  void write_log_row(std::ostream& out) const { format_log_row(out, log_row()); }

 private:
  Eigen::Vector3d steered_point(int k, int substeps) const;

  SpidarHardware hardware_;
  Trajectory trajectory_;
  std::size_t segment_hint_ = 0;  // the trajectory segment of the last sub-step (Trajectory::sample_at)
  Finger finger_;
  double time_s_ = 0.0;
  double trajectory_start_s_ = 0.0;  // session time of the trajectory's time 0 (hold_trajectory)
  DeviceState state_{};
  std::array<std::int64_t, kStringCount> counts_{};  // the first kStringCount of state_'s
  // Steered (closed loop): the target now and at the end of the next tick, and the hand's own push.
  bool steered_ = false;
  Vec3 target_now_m_{};
  Vec3 target_next_m_{};
  Vec3 hand_force_N_{};
};

}  // namespace impetus
