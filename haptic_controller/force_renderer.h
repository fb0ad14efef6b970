#pragma once
// Force rendering (paper §3.3, DESIGN.md §1 haptic tick step 4): the spring–damper between proxy D and finger C,
//     f_j = k_p (D_j − C_j) + k_d ((D_j − C_j) − (D_{j−1} − C_{j−1})) / Δt      (paper §3.3)
// with Δt the real elapsed time of this tick, clamped in magnitude to the device's maximum force. Any non-finite input
// or result gives zero force and a counted fault, and forgets the previous displacement so one NaN cannot poison the
// damper on the next tick. Owned by the servo thread; allocation-free, no exceptions.

#include <Eigen/Core>

#include <cstdint>

namespace impetus {

// Default damping when neither the flags nor the world give one: Colgate & Brown (1994) show a sampled virtual wall of
// stiffness K with sample period T needs damping b > K·T/2 to be passive; we take twice that, b = K·T, for margin
// against the backward-difference velocity's extra half-sample lag. 2 kN/m at 1 kHz → 2 N·s/m; 20 kN/m → 20 N·s/m.
inline constexpr double kPassivityDampingMargin = 2.0;
inline double passivity_damping_Nspm(double stiffness_Npm, double tick_period_s) {
  return kPassivityDampingMargin * 0.5 * stiffness_Npm * tick_period_s;
}

struct RenderedForce {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();  // on the finger
  bool clamped = false;                               // the magnitude was limited to max_force_N
  bool fault = false;                                 // something was not finite: force is zero
};

class ForceRenderer {
 public:
  explicit ForceRenderer(double max_force_N) : max_force_N_(max_force_N) {}

  // dt_s ≤ 0 (no time elapsed) renders the spring alone: a derivative over no time is undefined, not a fault.
  RenderedForce render(const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m, double stiffness_Npm,
                       double damping_Nspm, double dt_s);

  // Forget the previous displacement (no contact history: device re-attached, session restart).
  void reset() { has_previous_ = false; }

  std::uint64_t faults() const { return faults_; }
  std::uint64_t clamps() const { return clamps_; }

 private:
  double max_force_N_;
  Eigen::Vector3d previous_displacement_m_ = Eigen::Vector3d::Zero();
  bool has_previous_ = false;
  std::uint64_t faults_ = 0;
  std::uint64_t clamps_ = 0;
};

}  // namespace impetus
