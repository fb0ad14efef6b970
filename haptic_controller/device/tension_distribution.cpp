// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/tension_distribution.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// Tikhonov weight: large enough that the all-free 4×4 system (rank 3 without it) is well conditioned in double
// precision (condition ≈ 1/ε), small enough that the force bias ε·t/σ² stays far below kSaturationTolerance_N.
constexpr double kTensionRegularisation = 1e-6;
constexpr double kMinDirectionLength_m = 1e-9;
constexpr int kFaceCount = 81;  // 3^kStringCount

enum class Bound { lower, upper, free };

// Solves the n×n SPD system m·x = b in place (Cholesky; n ≤ 4). Returns false if not positive definite.
bool solve_spd(double (&m)[kStringCount][kStringCount], double (&b)[kStringCount], int n) {
  for (int j = 0; j < n; ++j) {
    double d = m[j][j];
    for (int k = 0; k < j; ++k) d -= m[j][k] * m[j][k];
    if (!(d > 0.0)) return false;
    m[j][j] = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double s = m[i][j];
      for (int k = 0; k < j; ++k) s -= m[i][k] * m[j][k];
      m[i][j] = s / m[j][j];
    }
  }
  for (int i = 0; i < n; ++i) {  // L y = b
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= m[i][k] * b[k];
    b[i] = s / m[i][i];
  }
  for (int i = n - 1; i >= 0; --i) {  // Lᵀ x = y
    double s = b[i];
    for (int k = i + 1; k < n; ++k) s -= m[k][i] * b[k];
    b[i] = s / m[i][i];
  }
  return true;
}

}  // namespace

TensionSolution distribute_tension(const Eigen::Vector3d& force_N, const Eigen::Vector3d& finger_m,
                                   const std::array<Eigen::Vector3d, kStringCount>& motors_m, double tension_min_N,
                                   double tension_max_N) {
  Eigen::Matrix<double, 3, kStringCount> a;
  for (int i = 0; i < kStringCount; ++i) {
    const Eigen::Vector3d d = motors_m[i] - finger_m;
    const double length = d.norm();
    a.col(i) = length > kMinDirectionLength_m ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
  }
  // Objective ½tᵀHt + cᵀt (+ const) with H = AᵀA + εI, c = −Aᵀf.
  const Eigen::Matrix4d h = a.transpose() * a + kTensionRegularisation * Eigen::Matrix4d::Identity();
  const Eigen::Vector4d c = -a.transpose() * force_N;

  Eigen::Vector4d best = Eigen::Vector4d::Constant(tension_min_N);
  double best_score = std::numeric_limits<double>::infinity();
  for (int face = 0; face < kFaceCount; ++face) {
    Bound bounds[kStringCount];
    int code = face;
    for (int i = 0; i < kStringCount; ++i, code /= 3) bounds[i] = static_cast<Bound>(code % 3);

    Eigen::Vector4d t;
    int free_index[kStringCount];
    int n_free = 0;
    for (int i = 0; i < kStringCount; ++i) {
      if (bounds[i] == Bound::free) {
        free_index[n_free++] = i;
        t[i] = 0.0;
      } else {
        t[i] = bounds[i] == Bound::lower ? tension_min_N : tension_max_N;
      }
    }
    if (n_free > 0) {
      // Stationary point over the free strings with the others fixed: H_FF t_F = −(c_F + H_FB t_B).
      double m[kStringCount][kStringCount];
      double b[kStringCount];
      for (int r = 0; r < n_free; ++r) {
        const int i = free_index[r];
        b[r] = -c[i];
        for (int k = 0; k < kStringCount; ++k) {
          if (bounds[k] != Bound::free) b[r] -= h(i, k) * t[k];
        }
        for (int q = 0; q < n_free; ++q) m[r][q] = h(i, free_index[q]);
      }
      if (!solve_spd(m, b, n_free)) continue;
      for (int r = 0; r < n_free; ++r) t[free_index[r]] = std::clamp(b[r], tension_min_N, tension_max_N);
    }
    const double score = 0.5 * t.dot(h * t) + c.dot(t);
    if (score < best_score) {
      best_score = score;
      best = t;
    }
  }

  TensionSolution solution;
  for (int i = 0; i < kStringCount; ++i) solution.tension_N[i] = best[i];
  solution.achieved_force_N = a * best;
  solution.saturated = !((solution.achieved_force_N - force_N).norm() <= kSaturationTolerance_N);  // NaN too
  return solution;
}

}  // namespace impetus
