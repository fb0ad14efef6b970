// SPDX-License-Identifier: Apache-2.0
#pragma once
// The hand holding the grip of the 8-string SPIDAR (common/spidar/grip_geometry.h): the grip and the fingertips that
// move with it as one rigid body, held by the hand's 6-DoF impedance about a target pose and pushed by the strings'
// wrench, as the fingertip (finger.h) is in 3 DoF:
//   m·a = k·(p_t − p) + b·(v_t − v) + f_device
//   I·α = k_r·θ + b_r·(ω_t − ω) + τ_device,   θ the rotation vector of the turn that takes the grip to the target.
// The inertia is isotropic (a ball held in the fingertips), so a free grip has no gyroscopic torque.
//
// Defaults and their physical meaning:
//   mass 0.15 kg             a 20 g grip and the ~0.1 kg of fingertips that move with it;
//   inertia 6e-5 kg·m²       that mass at the grip's 2 cm radius, where the fingertips hold it (m·r²);
//   stiffness 300 N/m,       the relaxed hand of finger.h (ζ ≈ 0.6 with this mass);
//   damping 8 N·s/m
//   rotational stiffness     a relaxed fingertip grasp resists twisting by 0.1–1 N·m/rad; 0.3 N·m/rad turns the grip
//   0.3 N·m/rad              by 0.1 rad under 0.03 N·m, about what a key takes to turn;
//   rotational damping       ζ = b_r/(2√(k_r·I)) ≈ 0.7, as the linear hand: settles in ~0.1 s.
//   6e-3 N·m·s/rad
// World frame, SI. Not thread-safe; allocation-free after construction.

#include "common/spidar/grip_strings.h"
#include "common/hand/finger.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace impetus {

struct GripHandParams {
  double mass_kg = 0.15;
  double inertia_kgm2 = 6e-5;
  double stiffness_Npm = 300.0;
  double damping_Nspm = 8.0;
  double rotational_stiffness_Nmprad = 0.3;
  double rotational_damping_Nmsprad = 6e-3;
  // Longest integration sub-step (s). The translation is integrated exactly (finger.h); the turn by semi-implicit
  // Euler, whose error grows with ω·h: the hand's own ω = √(k_r/I) = 71 rad/s, and a servo rendering 20 N·m/rad on
  // this inertia 580 rad/s, give ω·h ≤ 0.06 at 0.1 ms.
  double max_substep_s = 1e-4;
};

class GripHand {
 public:
  // Starts at rest at `start`. Throws std::invalid_argument naming the offending parameter (mass, inertia and the
  // stiffnesses > 0, dampings >= 0, max_substep_s > 0, all finite; a finite start).
  GripHand(const GripHandParams& params, const GripPose& start);

  // Sub-steps of at most max_substep_s that make up dt_s (> 0).
  int substeps_for(double dt_s) const { return finger_.substeps_for(dt_s); }

  // Advances h_s with `device` (force, and torque about the grip's centre) held over it, and the target at `target`
  // moving with the given velocities (world frame).
  void step(const GripPose& target, const Eigen::Vector3d& target_velocity_mps,
            const Eigen::Vector3d& target_angular_velocity_radps, const GripWrench& device, double h_s);

  GripPose pose() const { return {finger_.position_m(), orientation_}; }
  const Eigen::Vector3d& velocity_mps() const { return finger_.velocity_mps(); }
  const Eigen::Vector3d& angular_velocity_radps() const { return angular_velocity_radps_; }
  const GripHandParams& params() const { return params_; }

  // The rotation vector θ (rad) of the turn that takes `from` to `to`, world frame: the shorter way round.
  static Eigen::Vector3d turn_between(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to);

 private:
  GripHandParams params_;
  Finger finger_;  // the translation: a point mass held by the linear impedance
  Eigen::Quaterniond orientation_;
  Eigen::Vector3d angular_velocity_radps_ = Eigen::Vector3d::Zero();
};

}  // namespace impetus
