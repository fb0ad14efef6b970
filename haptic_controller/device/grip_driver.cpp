// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/grip_driver.h"

#include <algorithm>

namespace impetus {

GripDriver::GripDriver(const SpidarGripGeometry& geometry, const GripPose& start)
    : kinematics_(geometry), pose_(start), found_(start) {
  tensions_N_.fill(geometry.tension_min_N);
}

const GripPose* GripDriver::read(const GripCounts& counts) {
  ++counters_.readings;
  solve_ = kinematics_.pose(kinematics_.lengths_m(counts), pose_, found_);
  counters_.most_iterations = std::max(counters_.most_iterations, solve_.iterations);
  if (solve_.status != GripSolveStatus::ok) {
    ++counters_.bad_readings;
    have_pose_ = false;
    return nullptr;
  }
  pose_ = found_;
  have_pose_ = true;
  return &pose_;
}

const GripTensions& GripDriver::command(const GripWrench& wrench, bool render) {
  const SpidarGripGeometry& geometry = kinematics_.geometry();
  if (!render || !have_pose_) {
    tensions_N_.fill(geometry.tension_min_N);
    return tensions_N_;
  }
  tension_ = distribute_grip_tension(wrench, kinematics_.wrench_matrix(pose_), geometry.tension_min_N,
                                     geometry.tension_max_N);
  if (tension_.saturated) ++counters_.saturations;
  if (!tension_.closure) ++counters_.no_closure;
  tensions_N_ = tension_.tension_N;
  return tensions_N_;
}

}  // namespace impetus
