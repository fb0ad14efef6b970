// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/tension_distribution.h"

#include <Eigen/Geometry>

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

using StringDirections = Eigen::Matrix<double, 3, kStringCount>;

// A = [u_0 u_1 u_2 u_3], u_i the unit vector from the finger toward motor i (zero if they coincide).
StringDirections string_directions(const Eigen::Vector3d& finger_m,
                                   const std::array<Eigen::Vector3d, kStringCount>& motors_m) {
  StringDirections a;
  for (int i = 0; i < kStringCount; ++i) {
    const Eigen::Vector3d d = motors_m[i] - finger_m;
    const double length = d.norm();
    a.col(i) = length > kMinDirectionLength_m ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
  }
  return a;
}

double det3(const Eigen::Vector3d& x, const Eigen::Vector3d& y, const Eigen::Vector3d& z) { return x.dot(y.cross(z)); }

// Null weights below this (a determinant of three unit vectors) mean the finger is within ~1e-9 rad of the plane of
// three motors: the line solution would need unbounded tensions, so the faces decide.
constexpr double kMinNullWeight = 1e-9;

// The usual case in closed form (see the header): false if the strings do not surround the finger or the least
// tension on the exact-force line exceeds t_max somewhere.
bool distribute_on_null_line(const StringDirections& a, const Eigen::Vector3d& f, double t_min, double t_max,
                             Eigen::Vector4d& t) {
  const Eigen::Vector3d u0 = a.col(0), u1 = a.col(1), u2 = a.col(2), u3 = a.col(3);
  // A·n = 0 for n_i = (−1)^i det(A without column i): the cofactor expansion of a 4×4 with a repeated row.
  Eigen::Vector4d n(det3(u1, u2, u3), -det3(u0, u2, u3), det3(u0, u1, u3), -det3(u0, u1, u2));
  if (n.sum() < 0.0) n = -n;
  if (!(n.minCoeff() > kMinNullWeight)) return false;
  // A particular solution with t_3 = 0: [u0 u1 u2]·x = f by Cramer's rule; its determinant is −n_3 (before the sign
  // choice above), nonzero here.
  const double d = det3(u0, u1, u2);
  const Eigen::Vector4d particular(det3(f, u1, u2) / d, det3(u0, f, u2) / d, det3(u0, u1, f) / d, 0.0);
  int binding = 0;
  double lambda = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < kStringCount; ++i) {
    const double needed = (t_min - particular[i]) / n[i];
    if (needed > lambda) {
      lambda = needed;
      binding = i;
    }
  }
  t = particular + lambda * n;
  for (int i = 0; i < kStringCount; ++i) t[i] = std::max(t[i], t_min);  // others: at or above it, up to rounding
  t[binding] = t_min;
  return t.maxCoeff() <= t_max;
}

TensionSolution solution_of(const StringDirections& a, const Eigen::Vector4d& t, const Eigen::Vector3d& force_N) {
  TensionSolution solution;
  for (int i = 0; i < kStringCount; ++i) solution.tension_N[i] = t[i];
  solution.achieved_force_N = a * t;
  solution.saturated = !((solution.achieved_force_N - force_N).norm() <= kSaturationTolerance_N);  // NaN too
  return solution;
}

Eigen::Vector4d by_faces(const StringDirections& a, const Eigen::Vector3d& force_N, double tension_min_N,
                         double tension_max_N) {
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

  return best;
}

}  // namespace

TensionSolution distribute_tension(const Eigen::Vector3d& force_N, const Eigen::Vector3d& finger_m,
                                   const std::array<Eigen::Vector3d, kStringCount>& motors_m, double tension_min_N,
                                   double tension_max_N) {
  const StringDirections a = string_directions(finger_m, motors_m);
  Eigen::Vector4d t;
  if (force_N.allFinite() && distribute_on_null_line(a, force_N, tension_min_N, tension_max_N, t)) {
    return solution_of(a, t, force_N);
  }
  return solution_of(a, by_faces(a, force_N, tension_min_N, tension_max_N), force_N);
}

TensionSolution distribute_tension_by_faces(const Eigen::Vector3d& force_N, const Eigen::Vector3d& finger_m,
                                            const std::array<Eigen::Vector3d, kStringCount>& motors_m,
                                            double tension_min_N, double tension_max_N) {
  const StringDirections a = string_directions(finger_m, motors_m);
  return solution_of(a, by_faces(a, force_N, tension_min_N, tension_max_N), force_N);
}

}  // namespace impetus
