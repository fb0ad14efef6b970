// SPDX-License-Identifier: Apache-2.0
#pragma once
// The user's fingertip: a point mass held by the hand, which tracks the scripted target like a spring and damper
// (docs/architecture.md §1.2 "One device tick"). The device's string force pushes it off the target, as a real finger
// is pushed:
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
  // Longest integration sub-step (s). The hand's spring and damper are integrated exactly over any step (Finger::step),
  // so a sub-step only decides how often the device force is sampled and over what chord the target is taken as
  // straight (DeviceSim::tick): once per 1 kHz device tick by default. The servo's tensions are constant over a tick
  // anyway, and over a tick a finger at 1 m/s moves 1 mm, which turns a string 20–40 cm long by under 0.3 %. On the
  // normal-flip hard case the finger then stays within 20 µm of one sampled every 0.1 ms.
  double max_substep_s = 1e-3;
};

class Finger {
 public:
  // Starts at rest at `position_m`. Throws std::invalid_argument naming the offending parameter (mass and stiffness
  // > 0, damping >= 0, max_substep_s > 0, all finite).
  Finger(const FingerParams& params, const Eigen::Vector3d& position_m);

  // Sub-steps of at most max_substep_s that make up dt_s (> 0).
  int substeps_for(double dt_s) const;

  // Advances h_s with the device force held over it and the target moving at target_velocity_mps from target_m.
  // Exact for that input: the offset e = x − target − F/k obeys m·ë + b·ė + k·e = 0, whose state (e, ė) the step
  // maps by Φ = exp(A·h), A = [0 1; −k/m −b/m], computed once per step length. So the finger's frequency and decay
  // are the hand's at any step (a semi-implicit Euler step at 0.1 ms was off by 0.4 % in decay and took ten steps a
  // tick), and the step is stable for any stiffness.
  void step(const Eigen::Vector3d& target_m, const Eigen::Vector3d& target_velocity_mps,
            const Eigen::Vector3d& device_force_N, double h_s);

  // Holds the fingertip at rest where it is (a device whose hand let go stops it there).
  void stop() { velocity_mps_.setZero(); }

  const Eigen::Vector3d& position_m() const { return position_m_; }
  const Eigen::Vector3d& velocity_mps() const { return velocity_mps_; }
  const FingerParams& params() const { return params_; }

 private:
  FingerParams params_;
  // Φ for the last step length (step): row-major Φ00 Φ01 Φ10 Φ11.
  double transition_step_s_ = -1.0;
  double transition_[4] = {1.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_mps_ = Eigen::Vector3d::Zero();
};

}  // namespace impetus
