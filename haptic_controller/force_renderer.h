// SPDX-License-Identifier: Apache-2.0
#pragma once
// Force rendering (paper §3.3, docs/architecture.md §1.2 step 4): the spring–damper between proxy D and finger C,
//     f_j = k_p (D_j − C_j) + k_d ((D_j − C_j) − (D_{j−1} − C_{j−1})) / Δt      (paper §3.3)
// with Δt the real elapsed time of this tick, with its part along D − C kept non-negative (a contact pushes, it never
// pulls: the damper brakes an approach but does not drag the finger after a surface that lets go), then clamped in
// magnitude to the device's maximum force. Any non-finite input
// or result gives zero force and a counted fault, and forgets the previous displacement so one NaN cannot poison the
// damper on the next tick. Owned by the servo thread; allocation-free, no exceptions.

#include <Eigen/Core>

#include <cstdint>

namespace impetus {

// Default damping when neither the flags nor the world give one: k_d = K·T (2 N·s/m at 2 kN/m and 1 kHz). Colgate &
// Brown (1994) bound a sampled wall by the device's *physical* damping, b > K·T/2 + |B| with B the virtual damper, so in
// their analysis a virtual damper buys no passivity. What it buys is a stable finger on the wall: with the hand's
// 8 N·s/m, the exact sampled-data model of hard case 1 (docs/hard_cases.md) puts the stability limit at 80 kN/m for
// k_d = K·T against 16 kN/m for k_d = 0, and the measured sweep agrees with it.
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
