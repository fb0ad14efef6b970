// SPDX-License-Identifier: Apache-2.0
#pragma once
// The user's fingertip: a point mass held by the hand, which tracks the scripted target like a spring and damper
// (DESIGN.md §1 "One device tick"). The device's string force pushes it off the target, as a real finger is pushed:
//   m·a = k_h·(target − x) + b_h·(target_velocity − v) + F_device.
//
// Defaults and their physical meaning:
//   mass 0.1 kg          the fingertip plus the part of the hand that moves with it in a light tap;
//   stiffness 300 N/m    a relaxed finger/hand (measured arm and finger impedances span ~100–1000 N/m); a 3 N
//                        contact force deflects the finger 1 cm from where the person aims;
//   damping 8 N·s/m      ζ = b/(2√(k·m)) ≈ 0.73: the finger settles after a push with ~3.5 % overshoot, in
//                        ~4/(ζ·ω) ≈ 0.1 s (ω = √(k/m) ≈ 55 rad/s, 8.7 Hz: human limb resonances are a few Hz to ~10 Hz).
// World frame, SI units. Not thread-safe.

#include <Eigen/Core>

namespace impetus {

struct FingerParams {
  double mass_kg = 0.1;
  double hand_stiffness_Npm = 300.0;
  double hand_damping_Nspm = 8.0;
  // Longest integration sub-step (s): 0.1 ms gives 10 sub-steps per 1 kHz device tick, so the target and the string
  // directions are sampled much faster than the finger moves. A shorter step is used if the stiffness or damping
  // demand it (see Finger::substeps_for).
  double max_substep_s = 1e-4;
};

class Finger {
 public:
  // Starts at rest at `position_m`. Throws std::invalid_argument naming the offending parameter (mass and stiffness
  // > 0, damping >= 0, max_substep_s > 0, all finite).
  Finger(const FingerParams& params, const Eigen::Vector3d& position_m);

  // Sub-steps needed to advance dt_s (> 0) accurately: h ≤ max_substep_s and h·max(ω, b/m) ≤ 0.05.
  int substeps_for(double dt_s) const;

  // Advances one sub-step h_s with the target and the device force held over it. Semi-implicit: the velocity is
  // updated first (spring force at the current position, hand damping implicit in the new velocity), then the
  // position with the new velocity. This symplectic scheme keeps the oscillation's energy bounded for ω·h < 2 and the
  // implicit damping is unconditionally stable. With ω·h ≤ 0.05 the frequency error is ~(ω·h)²/24 < 0.02 % and the
  // decay rate is off by ~(b/m)·h/2, ≤ 2.5 % (0.4 % at the defaults).
  void step(const Eigen::Vector3d& target_m, const Eigen::Vector3d& target_velocity_mps,
            const Eigen::Vector3d& device_force_N, double h_s);

  const Eigen::Vector3d& position_m() const { return position_m_; }
  const Eigen::Vector3d& velocity_mps() const { return velocity_mps_; }
  const FingerParams& params() const { return params_; }

 private:
  FingerParams params_;
  double fastest_rate_per_s_;  // max(ω, b/m): the quickest time scale the step must resolve
  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_mps_ = Eigen::Vector3d::Zero();
};

}  // namespace impetus
