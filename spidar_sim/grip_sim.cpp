// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/grip_sim.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

Eigen::Matrix<double, kGripStringCount, 1> as_vector(const GripTensions& tensions_N) {
  return Eigen::Map<const Eigen::Matrix<double, kGripStringCount, 1>>(tensions_N.data());
}

}  // namespace

GripSim::GripSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, const GripPose& start)
    : strings_(geometry), hand_(hand, start) {
  if (!(geometry.tension_min_N >= 0.0 && geometry.tension_max_N >= geometry.tension_min_N &&
        std::isfinite(geometry.tension_max_N))) {
    throw std::invalid_argument("grip SPIDAR: tensions need 0 <= tension_min_N <= tension_max_N, finite");
  }
  tensions_N_.fill(geometry.tension_min_N);
  counts_ = strings_.encoder_counts(hand_.pose());
}

const GripCounts& GripSim::tick(const GripTensions& commanded_N, const GripPose& target,
                                const Eigen::Vector3d& target_velocity_mps,
                                const Eigen::Vector3d& target_angular_velocity_radps, double dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) {
    throw std::invalid_argument("GripSim::tick: dt_s must be finite and > 0, got " + std::to_string(dt_s));
  }
  const SpidarGripGeometry& geometry = strings_.geometry();
  for (int k = 0; k < kGripStringCount; ++k) {
    // A non-finite command is a broken servo: the motor holds its minimum, as when no command comes.
    const double command = std::isfinite(commanded_N[k]) ? commanded_N[k] : geometry.tension_min_N;
    tensions_N_[k] = std::clamp(command, geometry.tension_min_N, geometry.tension_max_N);
  }
  const int substeps = hand_.substeps_for(dt_s);
  const double h_s = dt_s / substeps;
  GripPose aim = target;
  for (int s = 0; s < substeps; ++s) {
    // The target over the tick: where it is at the tick's start, moved on by its velocities sub-step by sub-step.
    const double ahead_s = s * h_s;
    aim.position_m = target.position_m + ahead_s * target_velocity_mps;
    const Eigen::Vector3d turned = ahead_s * target_angular_velocity_radps;
    const double angle_rad = turned.norm();
    aim.orientation = angle_rad > 0.0
                          ? Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, turned / angle_rad)) * target.orientation
                          : target.orientation;
    const GripWrench device = strings_.wrench_matrix(hand_.pose()) * as_vector(tensions_N_);
    hand_.step(aim, target_velocity_mps, target_angular_velocity_radps, device, h_s);
  }
  time_s_ += dt_s;
  counts_ = strings_.encoder_counts(hand_.pose());
  return counts_;
}

GripWrench GripSim::wrench() const { return strings_.wrench_matrix(hand_.pose()) * as_vector(tensions_N_); }

}  // namespace impetus
