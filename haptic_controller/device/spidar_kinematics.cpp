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

  // Gauss–Newton on r_i = |x − m_i| − l_i over all four strings: JᵀJ·δ = Jᵀr with the rows u_i = (x − m_i)/|x − m_i|.
  // JᵀJ is symmetric, so δ = adj(JᵀJ)·Jᵀr / det from its six cofactors: fewer operations than a general 3×3 inverse.
  for (int step = 0; step < kGaussNewtonSteps; ++step) {
    double a00 = 0.0, a01 = 0.0, a02 = 0.0, a11 = 0.0, a12 = 0.0, a22 = 0.0;  // JᵀJ
    double b0 = 0.0, b1 = 0.0, b2 = 0.0;                                      // Jᵀr
    for (int i = 0; i < kStringCount; ++i) {
      const Eigen::Vector3d d = x - motors_m_[i];
      const double length = d.norm();
      if (length < kMinDirectionLength_m) continue;
      const double inverse_length = 1.0 / length;
      const double u0 = d.x() * inverse_length, u1 = d.y() * inverse_length, u2 = d.z() * inverse_length;
      const double residual = length - lengths_m[i];
      a00 += u0 * u0;
      a01 += u0 * u1;
      a02 += u0 * u2;
      a11 += u1 * u1;
      a12 += u1 * u2;
      a22 += u2 * u2;
      b0 += u0 * residual;
      b1 += u1 * residual;
      b2 += u2 * residual;
    }
    const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
    const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    if (!(std::abs(det) > kMinNormalDeterminant)) break;  // degenerate geometry: keep the closed form
    const double inverse_det = 1.0 / det;
    x.x() -= (c00 * b0 + c01 * b1 + c02 * b2) * inverse_det;
    x.y() -= (c01 * b0 + c11 * b1 + c12 * b2) * inverse_det;
    x.z() -= (c02 * b0 + c12 * b1 + c22 * b2) * inverse_det;
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
