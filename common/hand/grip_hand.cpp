// SPDX-License-Identifier: Apache-2.0
#include "common/hand/grip_hand.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

void require(bool ok, const char* field, const char* reason) {
  if (!ok) throw std::invalid_argument(std::string("grip hand: ") + field + " " + reason);
}

FingerParams linear_part(const GripHandParams& params) {
  FingerParams linear;
  linear.mass_kg = params.mass_kg;
  linear.hand_stiffness_Npm = params.stiffness_Npm;
  linear.hand_damping_Nspm = params.damping_Nspm;
  linear.max_substep_s = params.max_substep_s;
  return linear;
}

// exp of a rotation vector, as a unit quaternion.
Eigen::Quaterniond turn_of(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (!(angle > 0.0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

}  // namespace

GripHand::GripHand(const GripHandParams& params, const GripPose& start)
    : params_(params), finger_(linear_part(params), start.position_m), orientation_(start.orientation.normalized()) {
  require(std::isfinite(params.inertia_kgm2) && params.inertia_kgm2 > 0.0, "inertia_kgm2", "must be > 0");
  require(std::isfinite(params.rotational_stiffness_Nmprad) && params.rotational_stiffness_Nmprad > 0.0,
          "rotational_stiffness_Nmprad", "must be > 0");
  require(std::isfinite(params.rotational_damping_Nmsprad) && params.rotational_damping_Nmsprad >= 0.0,
          "rotational_damping_Nmsprad", "must be >= 0");
  require(start.orientation.coeffs().allFinite() && start.orientation.norm() > 0.0, "start orientation",
          "must be a finite, non-zero quaternion");
}

Eigen::Vector3d GripHand::turn_between(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to) {
  Eigen::Quaterniond turn = to * from.conjugate();
  if (turn.w() < 0.0) turn.coeffs() = -turn.coeffs();  // q and −q are one turn: the one of angle ≤ π
  const double sine = turn.vec().norm();
  if (!(sine > 0.0)) return Eigen::Vector3d::Zero();
  return 2.0 * std::atan2(sine, turn.w()) * (turn.vec() / sine);
}

void GripHand::step(const GripPose& target, const Eigen::Vector3d& target_velocity_mps,
                    const Eigen::Vector3d& target_angular_velocity_radps, const GripWrench& device, double h_s) {
  finger_.step(target.position_m, target_velocity_mps, device.head<3>(), h_s);
  // Semi-implicit Euler on the turn: the torque at the start of the step sets ω, and the grip turns by ω·h (world
  // frame, so the turn multiplies from the left). An isotropic inertia has no ω × I·ω term.
  const Eigen::Vector3d spring_Nm = params_.rotational_stiffness_Nmprad * turn_between(orientation_, target.orientation);
  const Eigen::Vector3d damper_Nm =
      params_.rotational_damping_Nmsprad * (target_angular_velocity_radps - angular_velocity_radps_);
  const Eigen::Vector3d torque_Nm = spring_Nm + damper_Nm + device.tail<3>();
  angular_velocity_radps_ += (h_s / params_.inertia_kgm2) * torque_Nm;
  orientation_ = (turn_of(h_s * angular_velocity_radps_) * orientation_).normalized();
}

}  // namespace impetus
