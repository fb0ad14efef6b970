// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/force_renderer.h"

#include <cmath>

namespace impetus {

RenderedForce ForceRenderer::render(const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m,
                                    double stiffness_Npm, double damping_Nspm, double dt_s) {
  RenderedForce out;
  const Eigen::Vector3d displacement_m = proxy_m - finger_m;  // D_j − C_j
  // Paper §3.3: f_j = k_p (D_j − C_j) + k_d ((D_j − C_j) − (D_{j−1} − C_{j−1})) / Δt.
  Eigen::Vector3d force_N = stiffness_Npm * displacement_m;
  if (has_previous_ && dt_s > 0.0) force_N += damping_Nspm * (displacement_m - previous_displacement_m_) / dt_s;

  if (!force_N.allFinite() || !std::isfinite(stiffness_Npm) || !std::isfinite(damping_Nspm) || !std::isfinite(dt_s)) {
    ++faults_;
    has_previous_ = false;
    out.fault = true;
    return out;
  }
  previous_displacement_m_ = displacement_m;
  has_previous_ = true;
  // A contact pushes, it never pulls: the damper may brake the finger's approach and its sliding, but the force's
  // part along the spring (D − C, the way the surface pushes) is never negative. Without this a surface that lets go
  // of the finger (a face turning away at an edge, an object moving off) drags it along by k_d times the release
  // speed (hard case 6: 0.5 N into a box the finger had slid off).
  const double depth_m = displacement_m.norm();
  if (depth_m > 0.0) {
    const Eigen::Vector3d push = displacement_m / depth_m;
    const double along_N = force_N.dot(push);
    if (along_N < 0.0) force_N -= along_N * push;
  } else {
    force_N.setZero();
  }

  const double magnitude_N = force_N.norm();
  if (magnitude_N > max_force_N_) {
    force_N *= max_force_N_ / magnitude_N;
    ++clamps_;
    out.clamped = true;
  }
  out.force_N = force_N;
  return out;
}

}  // namespace impetus
