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
