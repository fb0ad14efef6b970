// SPDX-License-Identifier: Apache-2.0
#pragma once
// Turns as rotation vectors (axis × angle, rad, world frame) and unit quaternions: the exponential map and its
// inverse, for the 6-DoF parts (the grip device, its hand, the tool). Allocation-free, header-only.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace impetus {

// exp: the unit quaternion of the turn by `rotation_vector` (the identity for a zero vector).
inline Eigen::Quaterniond turn_quaternion(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (!(angle > 0.0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

// log of to·from⁻¹: the rotation vector of the turn that takes `from` to `to` (both unit), the shorter way round
// (angle ≤ π; q and −q are one turn).
inline Eigen::Vector3d turn_between(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to) {
  Eigen::Quaterniond turn = to * from.conjugate();
  if (turn.w() < 0.0) turn.coeffs() = -turn.coeffs();
  const double sine = turn.vec().norm();
  if (!(sine > 0.0)) return Eigen::Vector3d::Zero();
  return 2.0 * std::atan2(sine, turn.w()) * (turn.vec() / sine);
}

// `orientation` turned by `rotation_vector` in the world frame (the turn multiplies from the left), renormalised.
inline Eigen::Quaterniond turned(const Eigen::Quaterniond& orientation, const Eigen::Vector3d& rotation_vector) {
  return (turn_quaternion(rotation_vector) * orientation).normalized();
}

}  // namespace impetus
