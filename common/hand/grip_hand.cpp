// SPDX-License-Identifier: Apache-2.0
#include "common/hand/grip_hand.h"

#include "common/contract/rotation.h"

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
  return impetus::turn_between(from, to);
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
  orientation_ = turned(orientation_, h_s * angular_velocity_radps_);
}

}  // namespace impetus
