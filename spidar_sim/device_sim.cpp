// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/device_sim.h"

#include "common/runtime/csv_line.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <stdexcept>
#include <string>
#include <utility>

namespace impetus {


std::string trajectory_problem(const Trajectory& trajectory, const SpidarGeometry& geometry) {
  const double half_m = 0.5 * geometry.frame_side_m;
  const auto outside = [&](const Vec3& point_m) {
    for (int a = 0; a < 3; ++a) {
      if (!(std::abs(point_m[a] - geometry.centre_m[a]) <= half_m)) return true;
    }
    return false;
  };
  // A line stays inside a cube when its ends do; an arc is looked at in 64 places (a bulge between two of them is
  // at most r·(1 − cos(π/64)), 0.1 % of its radius).
  constexpr int kArcSamples = 64;
  for (const TrajectorySegment& segment : trajectory.segments()) {
    const double span_s = segment.end_s - segment.begin_s;
    const int samples = segment.path == TrajectorySegment::Path::arc ? kArcSamples : 1;
    for (int k = 0; k <= samples; ++k) {
      const double t_s = segment.begin_s + span_s * static_cast<double>(k) / samples;
      const Vec3 point_m = trajectory.position_at(t_s);
      if (!outside(point_m)) continue;
      char text[256];
      std::snprintf(text, sizeof text,
                    "at t = %g s the target (%g, %g, %g) m is outside the device's frame, the %g m cube around "
                    "(%g, %g, %g) m, where the strings cannot hold the finger",
                    t_s, point_m[0], point_m[1], point_m[2], geometry.frame_side_m, geometry.centre_m[0],
                    geometry.centre_m[1], geometry.centre_m[2]);
      return text;
    }
  }
  return "";
}

namespace {

const Trajectory& checked(const Trajectory& trajectory, const SpidarGeometry& geometry) {
  if (const std::string problem = trajectory_problem(trajectory, geometry); !problem.empty()) {
    throw TrajectoryError(trajectory.description() + ": " + problem);
  }
  return trajectory;
}

}  // namespace

DeviceSim::DeviceSim(const SpidarGeometry& geometry, HardwareParams hardware, FingerParams finger,
                     Trajectory trajectory)
    : hardware_(geometry, hardware),
      trajectory_(std::move(trajectory)),
      finger_(finger, to_eigen(checked(trajectory_, geometry).position_at(0.0))) {
  counts_ = hardware_.encoder_counts(finger_.position_m());
  set_first_strings(counts_, state_.encoder_counts);
}

const DeviceState& DeviceSim::tick(const std::array<double, kStringCount>& commanded_tension_N, double dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0.0 && dt_s <= kMaxTick_s)) {
    throw std::invalid_argument("DeviceSim::tick: dt_s must be in (0, " + std::to_string(kMaxTick_s) + "] s, got " +
                                std::to_string(dt_s));
  }
  // Motors without lag reach the command at once and hold it (SpidarHardware::apply with a zero time constant): one
  // application stands for the tick's every sub-step. With lag they approach it sub-step by sub-step, ten to a time
  // constant, so the force the finger feels follows the tension's rise.
  const double lag_s = hardware_.params().motor_time_constant_s;
  const bool motor_lag = lag_s > 0.0;
  int substeps = finger_.substeps_for(dt_s);
  if (motor_lag) substeps = std::max(substeps, static_cast<int>(std::ceil(dt_s / (0.1 * lag_s))));
  const double h_s = dt_s / substeps;
  if (!motor_lag) hardware_.apply(commanded_tension_N, h_s);
  for (int k = 0; k < substeps; ++k) {
    // The trajectory's time (it starts at 0 when nothing was held, so the subtraction is exact); a tick being held
    // spans [−dt_s, 0] of it, where the trajectory is its start.
    const double session_s = time_s_ + k * h_s;
    const double t_s = std::max(0.0, session_s - trajectory_start_s_);
    const double t_end_s = std::max(0.0, session_s + h_s - trajectory_start_s_);
    if (motor_lag) hardware_.apply(commanded_tension_N, h_s);
    Eigen::Vector3d force_N = hardware_.force_on_finger(finger_.position_m());
    // The target over the sub-step as the chord from where it is now to where it will be: the finger's step takes it
    // as moving in a straight line (Finger::step), and the chord ends the sub-step exactly on the trajectory (or, when
    // steered, on the straight line to the steered point).
    Eigen::Vector3d from_m;
    Eigen::Vector3d to_m;
    if (steered_) {
      from_m = steered_point(k, substeps);
      to_m = steered_point(k + 1, substeps);
      // Only a push is added: adding a zero would turn a −0 into +0 and part a replay from the trajectory's run.
      if (hand_force_N_ != Vec3{}) force_N += to_eigen(hand_force_N_);
    } else {
      from_m = to_eigen(trajectory_.sample_at(t_s, segment_hint_).position_m);
      to_m = to_eigen(trajectory_.sample_at(t_end_s, segment_hint_).position_m);
    }
    finger_.step(from_m, (to_m - from_m) / h_s, force_N, h_s);
  }
  target_now_m_ = target_next_m_;
  time_s_ += dt_s;
  ++state_.tick;
  counts_ = hardware_.encoder_counts(finger_.position_m());
  set_first_strings(counts_, state_.encoder_counts);
  return state_;
}

void DeviceSim::steer(const Vec3& target_m) {
  if (!steered_) target_now_m_ = trajectory_.position_at(trajectory_time_s());
  steered_ = true;
  target_next_m_ = target_m;
}

void DeviceSim::set_hand_force(const Vec3& force_N) {
  if (!steered_) steer(trajectory_.position_at(trajectory_time_s()));
  hand_force_N_ = force_N;
}

// Point k of `substeps` along the tick's straight line from target_now_m_ to target_next_m_; the ends are the two
// points themselves (not now + (next − now)·1, which may round off the point the caller gave).
Eigen::Vector3d DeviceSim::steered_point(int k, int substeps) const {
  if (k == 0) return to_eigen(target_now_m_);
  if (k == substeps) return to_eigen(target_next_m_);
  const Eigen::Vector3d now_m = to_eigen(target_now_m_);
  return now_m + (to_eigen(target_next_m_) - now_m) * (static_cast<double>(k) / substeps);
}

nlohmann::json DeviceSim::summary_fields() const {
  const FingerParams& finger = finger_.params();
  const SpidarGeometry& geometry = hardware_.geometry();
  return {{"finger_mass_kg", finger.mass_kg},
          {"hand_stiffness_Npm", finger.hand_stiffness_Npm},
          {"hand_damping_Nspm", finger.hand_damping_Nspm},
          {"motor_time_constant_s", hardware_.params().motor_time_constant_s},
          {"frame_side_m", geometry.frame_side_m},
          {"metres_per_count", geometry.metres_per_count},
          {"tension_min_N", geometry.tension_min_N},
          {"tension_max_N", geometry.tension_max_N},
          {"max_force_N", geometry.max_force_N}};
}

const char* DeviceSim::log_header() {
  return "time_s,target_x_m,target_y_m,target_z_m,finger_x_m,finger_y_m,finger_z_m,"
         "finger_vx_mps,finger_vy_mps,finger_vz_mps,force_x_N,force_y_N,force_z_N,"
         "tension_0_N,tension_1_N,tension_2_N,tension_3_N,count_0,count_1,count_2,count_3";
}

DeviceLogRow DeviceSim::log_row() const {
  return {time_s_, target_m(), finger_m(), finger_velocity_mps(), device_force_N(), tensions_N(), encoder_counts()};
}

void DeviceSim::format_log_row(std::ostream& out, const DeviceLogRow& row) {
  CsvLine line(out);
  line.number(row.time_s).numbers(row.target_m).numbers(row.finger_m).numbers(row.finger_velocity_mps);
  line.numbers(row.force_N);
  for (const double t : row.tension_N) line.number(t);
  for (const std::int64_t c : row.encoder_counts) line.integer(c);
}

}  // namespace impetus
