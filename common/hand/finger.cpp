// SPDX-License-Identifier: Apache-2.0
#include "common/hand/finger.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {

namespace {

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
}

int Finger::substeps_for(double dt_s) const {
  return std::max(1, static_cast<int>(std::ceil(dt_s / params_.max_substep_s - 1e-9)));  // 1e-9: 1 ms / 1 ms is 1
}

// exp(A·h) for A = [0 1; −k/m −b/m], by scaling and squaring: the Taylor series of A·h/2^s, with ‖A·h/2^s‖ ≤ 1/4 so
// 16 terms leave under 1e-18, squared s times.
static void transition(double k_over_m, double b_over_m, double h_s, double out[4]) {
  double a[4] = {0.0, h_s, -k_over_m * h_s, -b_over_m * h_s};
  const double norm = std::max(std::fabs(a[1]), std::fabs(a[2]) + std::fabs(a[3]));
  int squarings = 0;
  double scale = 1.0;
  while (norm * scale > 0.25 && squarings < 60) {
    scale *= 0.5;
    ++squarings;
  }
  for (double& x : a) x *= scale;
  double sum[4] = {1.0, 0.0, 0.0, 1.0};
  double term[4] = {1.0, 0.0, 0.0, 1.0};
  for (int n = 1; n <= 16; ++n) {
    const double next[4] = {(term[0] * a[0] + term[1] * a[2]) / n, (term[0] * a[1] + term[1] * a[3]) / n,
                            (term[2] * a[0] + term[3] * a[2]) / n, (term[2] * a[1] + term[3] * a[3]) / n};
    for (int i = 0; i < 4; ++i) {
      term[i] = next[i];
      sum[i] += term[i];
    }
  }
  for (int i = 0; i < squarings; ++i) {
    const double squared[4] = {sum[0] * sum[0] + sum[1] * sum[2], sum[0] * sum[1] + sum[1] * sum[3],
                               sum[2] * sum[0] + sum[3] * sum[2], sum[2] * sum[1] + sum[3] * sum[3]};
    for (int j = 0; j < 4; ++j) sum[j] = squared[j];
  }
  for (int i = 0; i < 4; ++i) out[i] = sum[i];
}

void Finger::step(const Eigen::Vector3d& target_m, const Eigen::Vector3d& target_velocity_mps,
                  const Eigen::Vector3d& device_force_N, double h_s) {
  const double k = params_.hand_stiffness_Npm;
  const double m = params_.mass_kg;
  if (h_s != transition_step_s_) {
    transition(k / m, params_.hand_damping_Nspm / m, h_s, transition_);
    transition_step_s_ = h_s;
  }
  // Offsets from where the hand holds the finger against the force: the equilibrium moves with the target.
  const Eigen::Vector3d rest_m = target_m + device_force_N / k;
  const Eigen::Vector3d offset_m = position_m_ - rest_m;
  const Eigen::Vector3d offset_velocity_mps = velocity_mps_ - target_velocity_mps;
  position_m_ = rest_m + h_s * target_velocity_mps + transition_[0] * offset_m + transition_[1] * offset_velocity_mps;
  velocity_mps_ = target_velocity_mps + transition_[2] * offset_m + transition_[3] * offset_velocity_mps;
}

}  // namespace impetus
