// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/finger.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {

namespace {

// Largest (fastest rate × step): ~125 steps per oscillation period, which keeps the scheme's frequency and decay
// errors at the per-cent level or below (see Finger::step) for any stiffness and damping a user picks.
constexpr double kMaxRateTimesStep = 0.05;

void require(bool ok, const char* field, const char* reason) {
  if (!ok) throw std::invalid_argument(std::string("finger: ") + field + " " + reason);
}

}  // namespace

Finger::Finger(const FingerParams& params, const Eigen::Vector3d& position_m)
    : params_(params), position_m_(position_m) {
  require(std::isfinite(params.mass_kg) && params.mass_kg > 0.0, "mass_kg", "must be > 0");
  require(std::isfinite(params.hand_stiffness_Npm) && params.hand_stiffness_Npm > 0.0, "hand_stiffness_Npm",
          "must be > 0");
  require(std::isfinite(params.hand_damping_Nspm) && params.hand_damping_Nspm >= 0.0, "hand_damping_Nspm",
          "must be >= 0");
  require(std::isfinite(params.max_substep_s) && params.max_substep_s > 0.0, "max_substep_s", "must be > 0");
  require(position_m.allFinite(), "initial position", "must be finite");
  const double omega_radps = std::sqrt(params.hand_stiffness_Npm / params.mass_kg);
  fastest_rate_per_s_ = std::max(omega_radps, params.hand_damping_Nspm / params.mass_kg);
}

int Finger::substeps_for(double dt_s) const {
  const double step_s = std::min(params_.max_substep_s, kMaxRateTimesStep / fastest_rate_per_s_);
  return std::max(1, static_cast<int>(std::ceil(dt_s / step_s)));
}

void Finger::step(const Eigen::Vector3d& target_m, const Eigen::Vector3d& target_velocity_mps,
                  const Eigen::Vector3d& device_force_N, double h_s) {
  const double k = params_.hand_stiffness_Npm;
  const double b = params_.hand_damping_Nspm;
  const double m = params_.mass_kg;
  // m·(v' − v)/h = k·(target − x) + b·(target_velocity − v') + F   ⇒   solve for v' (damping implicit)
  const Eigen::Vector3d explicit_force_N = k * (target_m - position_m_) + b * target_velocity_mps + device_force_N;
  velocity_mps_ = (m * velocity_mps_ + h_s * explicit_force_N) / (m + h_s * b);
  position_m_ += h_s * velocity_mps_;
}

}  // namespace impetus
