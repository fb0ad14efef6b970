// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/spidar_hardware.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {

namespace {

// Below this length (m) a string has no usable direction; far shorter than any real pulley-to-cap distance.
constexpr double kMinStringLength_m = 1e-9;

void require(bool ok, const char* field, const char* reason) {
  if (!ok) throw std::invalid_argument(std::string("spidar hardware: ") + field + " " + reason);
}

}  // namespace

SpidarHardware::SpidarHardware(const SpidarGeometry& geometry, const HardwareParams& params)
    : geometry_(geometry), params_(params) {
  require(std::isfinite(geometry.frame_side_m) && geometry.frame_side_m > 0.0, "frame_side_m", "must be > 0");
  require(all_finite(geometry.centre_m), "centre_m", "must be finite");
  require(std::isfinite(geometry.metres_per_count) && geometry.metres_per_count > 0.0, "metres_per_count",
          "must be > 0");
  require(std::isfinite(geometry.tension_min_N) && geometry.tension_min_N >= 0.0, "tension_min_N", "must be >= 0");
  require(std::isfinite(geometry.tension_max_N) && geometry.tension_max_N >= geometry.tension_min_N, "tension_max_N",
          "must be >= tension_min_N");
  require(std::isfinite(params.motor_time_constant_s) && params.motor_time_constant_s >= 0.0,
          "motor_time_constant_s", "must be >= 0");

  const auto motors = geometry.motor_positions_m();
  for (int i = 0; i < kStringCount; ++i) motor_m_[i] = to_eigen(motors[i]);
  tension_N_.fill(geometry.tension_min_N);
}

void SpidarHardware::apply(const Tensions& commanded_tension_N, double dt_s) {
  // Exact solution of dt/dτ = (c − t)/τ over dt for a held command c: t ← c + (t − c)·e^(−dt/τ).
  const double decay =
      params_.motor_time_constant_s > 0.0 ? std::exp(-dt_s / params_.motor_time_constant_s) : 0.0;
  for (int i = 0; i < kStringCount; ++i) {
    const double raw = commanded_tension_N[i];
    const double command = std::isfinite(raw)
                               ? std::clamp(raw, geometry_.tension_min_N, geometry_.tension_max_N)
                               : geometry_.tension_min_N;
    tension_N_[i] = command + (tension_N_[i] - command) * decay;
  }
}

std::array<Eigen::Vector3d, kStringCount> SpidarHardware::string_directions(const Eigen::Vector3d& finger_m) const {
  std::array<Eigen::Vector3d, kStringCount> directions;
  for (int i = 0; i < kStringCount; ++i) {
    const Eigen::Vector3d to_motor = motor_m_[i] - finger_m;
    const double length = to_motor.norm();
    directions[i] = length > kMinStringLength_m ? Eigen::Vector3d(to_motor / length) : Eigen::Vector3d::Zero();
  }
  return directions;
}

Eigen::Vector3d SpidarHardware::force_on_finger(const Eigen::Vector3d& finger_m) const {
  const auto directions = string_directions(finger_m);
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  for (int i = 0; i < kStringCount; ++i) force_N += tension_N_[i] * directions[i];
  return force_N;
}

std::array<double, kStringCount> SpidarHardware::string_lengths_m(const Eigen::Vector3d& finger_m) const {
  std::array<double, kStringCount> lengths{};
  for (int i = 0; i < kStringCount; ++i) lengths[i] = (motor_m_[i] - finger_m).norm();
  return lengths;
}

SpidarHardware::Counts SpidarHardware::encoder_counts(const Eigen::Vector3d& finger_m) const {
  const auto lengths = string_lengths_m(finger_m);
  Counts counts{};
  for (int i = 0; i < kStringCount; ++i) counts[i] = std::llround(lengths[i] / geometry_.metres_per_count);
  return counts;
}

}  // namespace impetus
