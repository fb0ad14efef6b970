// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/spidar_kinematics.h"

#include <Eigen/LU>

#include <cmath>

namespace impetus {
namespace {

// Two Gauss–Newton steps: the closed form is already exact for consistent lengths; quantised lengths (±½ count) are
// inconsistent by a few µm, and one step reaches the least-squares point to well below a count, the second confirms.
constexpr int kGaussNewtonSteps = 2;
// A string shorter than this has no usable direction (the finger would sit in the pulley); its row is skipped.
constexpr double kMinDirectionLength_m = 1e-9;
// JᵀJ is a sum of four unit dyads (eigenvalues ≈ 4/3 inside the frame); a determinant this small means the finger is
// outside any sensible workspace, and a Newton step there would be noise.
constexpr double kMinNormalDeterminant = 1e-12;

}  // namespace

SpidarKinematics::SpidarKinematics(const SpidarGeometry& geometry) : geometry_(geometry) {
  const auto motors = geometry.motor_positions_m();
  for (int i = 0; i < kStringCount; ++i) motors_m_[i] = to_eigen(motors[i]);
  Eigen::Matrix3d differences;
  for (int i = 1; i < kStringCount; ++i) differences.row(i - 1) = 2.0 * (motors_m_[i] - motors_m_[0]).transpose();
  // Nonsingular for any tetrahedral layout: the three edges from motor 0 span space.
  difference_inverse_ = differences.inverse();
}

StringLengths SpidarKinematics::string_lengths_m(const EncoderCounts& counts) const {
  StringLengths lengths{};
  for (int i = 0; i < kStringCount; ++i) lengths[i] = static_cast<double>(counts[i]) * geometry_.metres_per_count;
  return lengths;
}

bool SpidarKinematics::finger_position(const StringLengths& lengths_m, Eigen::Vector3d& finger_m) const {
  // |x − m_i|² − |x − m_0|² = l_i² − l_0²  ⇔  2(m_i − m_0)·x = |m_i|² − |m_0|² − l_i² + l_0²  (linear in x).
  Eigen::Vector3d rhs;
  for (int i = 1; i < kStringCount; ++i) {
    rhs[i - 1] = motors_m_[i].squaredNorm() - motors_m_[0].squaredNorm() - lengths_m[i] * lengths_m[i] +
                 lengths_m[0] * lengths_m[0];
  }
  Eigen::Vector3d x = difference_inverse_ * rhs;

  // Gauss–Newton on r_i = |x − m_i| − l_i over all four strings (normal equations, 3×3).
  for (int step = 0; step < kGaussNewtonSteps; ++step) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (int i = 0; i < kStringCount; ++i) {
      const Eigen::Vector3d d = x - motors_m_[i];
      const double length = d.norm();
      if (length < kMinDirectionLength_m) continue;
      const Eigen::Vector3d row = d / length;
      jtj += row * row.transpose();
      jtr += row * (length - lengths_m[i]);
    }
    const double det = jtj.determinant();
    if (!(std::abs(det) > kMinNormalDeterminant)) break;  // degenerate geometry: keep the closed form
    x -= jtj.inverse() * jtr;
  }
  if (!x.allFinite()) return false;
  finger_m = x;
  return true;
}

StringLengths SpidarKinematics::string_lengths_m(const Eigen::Vector3d& finger_m) const {
  StringLengths lengths{};
  for (int i = 0; i < kStringCount; ++i) lengths[i] = (finger_m - motors_m_[i]).norm();
  return lengths;
}

EncoderCounts SpidarKinematics::encoder_counts(const Eigen::Vector3d& finger_m) const {
  const StringLengths lengths = string_lengths_m(finger_m);
  EncoderCounts counts{};
  for (int i = 0; i < kStringCount; ++i) counts[i] = std::llround(lengths[i] / geometry_.metres_per_count);
  return counts;
}

}  // namespace impetus
