// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/grip_tension.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

using Tensions = Eigen::Matrix<double, kGripStringCount, 1>;
using NullBasis = Eigen::Matrix<double, kGripStringCount, 2>;

// Feasible to rounding: 10⁻⁹ of the motors' range (the candidates' own rounding is ~10⁻¹⁵ of it), so the clamp into
// the box afterwards moves a tension by nanonewtons at most.
constexpr double kFeasible = 1e-9;

// Where the lines a_i·λ = b_i and a_j·λ = b_j meet (Cramer's rule; det = a_i × a_j, non-zero).
Eigen::Vector2d meet(const Eigen::Vector2d& ai, const Eigen::Vector2d& aj, double bi, double bj, double det) {
  return Eigen::Vector2d((bi * aj.y() - bj * ai.y()) / det, (ai.x() * bj - aj.x() * bi) / det);
}

// The largest s in [0, 1] for which some λ has t_min ≤ s·t_p + N·λ ≤ t_max: a linear programme in (λ, s), whose
// optimum is a vertex where two of the sixteen limits meet (the polytope is bounded in λ). Two limits meet on a line
// λ(s) = λ₀ + s·λ₁, along which each string's tension is affine in s, α_k + β_k·s; the sixteen limits then bound s
// to an interval, and the largest end over the 120 pairs is the answer. One pass over the corners, as one
// feasibility test costs, exact to rounding. Called with s = 0 feasible, so the answer is at least 0.
double largest_scale(const Tensions& least, const NullBasis& n, double lo, double hi) {
  const double tolerance = kFeasible * (hi - lo);
  constexpr int kLines = 2 * kGripStringCount;
  double largest = 0.0;
  for (int i = 0; i < kLines; ++i) {
    for (int j = i + 1; j < kLines; ++j) {
      const Eigen::Vector2d ai = n.row(i / 2).transpose();
      const Eigen::Vector2d aj = n.row(j / 2).transpose();
      const double det = ai.x() * aj.y() - ai.y() * aj.x();
      if (std::abs(det) < 1e-12) continue;  // parallel: a string's two limits, or two strings alike
      // a_i·λ = c_i − s·t_p,i and likewise for j: λ₀ solves the constants, λ₁ the coefficients of s.
      const Eigen::Vector2d lambda0 = meet(ai, aj, i % 2 ? hi : lo, j % 2 ? hi : lo, det);
      const Eigen::Vector2d lambda1 = meet(ai, aj, -least[i / 2], -least[j / 2], det);
      double from = 0.0;
      double to = 1.0;
      for (int k = 0; k < kGripStringCount && from <= to; ++k) {
        const double alpha = n.row(k).dot(lambda0);
        const double beta = least[k] + n.row(k).dot(lambda1);
        // lo − tol ≤ α + β·s ≤ hi + tol.
        if (std::abs(beta) < 1e-15) {
          if (alpha < lo - tolerance || alpha > hi + tolerance) to = -1.0;
        } else if (beta > 0.0) {
          from = std::max(from, (lo - tolerance - alpha) / beta);
          to = std::min(to, (hi + tolerance - alpha) / beta);
        } else {
          from = std::max(from, (hi + tolerance - alpha) / beta);
          to = std::min(to, (lo - tolerance - alpha) / beta);
        }
      }
      if (from <= to) largest = std::max(largest, to);
    }
  }
  return largest;
}

// The λ nearest the origin with t_min ≤ base + N·λ ≤ t_max (header: the origin, the feet of the perpendiculars on the
// sixteen limit lines, and their pairwise corners). False if no candidate is feasible: the polygon is empty (it is
// bounded, N having full column rank, so a non-empty one has a feasible corner). With `any`, whether the polygon is
// empty only: the first feasible corner ends the search.
bool nearest_feasible(const Tensions& base, const NullBasis& n, double lo, double hi, Eigen::Vector2d& best,
                      bool any = false) {
  const double tolerance = kFeasible * (hi - lo);
  const auto feasible = [&](const Eigen::Vector2d& lambda) {
    for (int k = 0; k < kGripStringCount; ++k) {
      const double t = base[k] + n.row(k).dot(lambda);
      if (t < lo - tolerance || t > hi + tolerance) return false;
    }
    return true;
  };
  // The sixteen lines a_j·λ = b_j: string k at its minimum (j = 2k) or its maximum (j = 2k + 1).
  constexpr int kLines = 2 * kGripStringCount;
  std::array<Eigen::Vector2d, kLines> a;
  std::array<double, kLines> b;
  for (int k = 0; k < kGripStringCount; ++k) {
    a[2 * k] = a[2 * k + 1] = n.row(k).transpose();
    b[2 * k] = lo - base[k];
    b[2 * k + 1] = hi - base[k];
  }
  double best_norm = std::numeric_limits<double>::infinity();
  const auto consider = [&](const Eigen::Vector2d& lambda) {
    const double norm = lambda.squaredNorm();
    if (norm < best_norm && feasible(lambda)) {
      best_norm = norm;
      best = lambda;
    }
  };
  for (int i = 0; i < kLines; ++i) {
    for (int j = i + 1; j < kLines; ++j) {
      const double det = a[i].x() * a[j].y() - a[i].y() * a[j].x();
      if (std::abs(det) < 1e-12) continue;  // parallel: a string's two limits, or two strings alike
      consider(meet(a[i], a[j], b[i], b[j], det));
      if (any && best_norm < std::numeric_limits<double>::infinity()) return true;
    }
  }
  if (any) return false;
  consider(Eigen::Vector2d::Zero());
  for (int j = 0; j < kLines; ++j) {
    const double length2 = a[j].squaredNorm();
    if (length2 > 1e-24) consider(b[j] / length2 * a[j]);
  }
  return best_norm < std::numeric_limits<double>::infinity();
}

}  // namespace

GripTensionSolution distribute_grip_tension(const GripWrench& wrench, const GripWrenchMatrix& w, double tension_min_N,
                                            double tension_max_N) {
  GripTensionSolution solution;
  const auto at_minimum = [&] {
    solution.tension_N.fill(tension_min_N);
    solution.achieved = w * Tensions::Constant(tension_min_N);
    solution.closure = false;
    solution.saturated = true;
    solution.scale = 0.0;
    return solution;
  };
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> factor(w * w.transpose());
  const auto pivots = factor.vectorD();
  if (!wrench.allFinite() || factor.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) {
    return at_minimum();  // no wrench to render, or a pose where the strings do not span the six directions
  }
  const Tensions least = w.transpose() * factor.solve(wrench);  // t_p = Wᵀ(W·Wᵀ)⁻¹·w, the least-norm exact answer
  // W's null space: the last two columns of Q in Wᵀ = Q·R (W has rank 6, checked above).
  const Eigen::HouseholderQR<Eigen::Matrix<double, kGripStringCount, 6>> qr(w.transpose());
  const Eigen::Matrix<double, kGripStringCount, kGripStringCount> q = qr.householderQ();
  const NullBasis n = q.rightCols<2>();

  Eigen::Vector2d lambda;
  double scale = 1.0;
  if (!nearest_feasible(least, n, tension_min_N, tension_max_N, lambda)) {
    if (!nearest_feasible(Tensions::Zero(), n, tension_min_N, tension_max_N, lambda, true)) return at_minimum();
    scale = largest_scale(least, n, tension_min_N, tension_max_N);
    // At the largest scale the polygon may have shrunk to a point that rounding puts just outside; the scale a
    // hair smaller (10⁻⁹ of it) always has one.
    if (!nearest_feasible(scale * least, n, tension_min_N, tension_max_N, lambda)) {
      scale *= 1.0 - 1e-9;
      if (!nearest_feasible(scale * least, n, tension_min_N, tension_max_N, lambda)) lambda.setZero();
    }
    solution.saturated = true;
  }
  const Tensions t = (scale * least + n * lambda).cwiseMax(tension_min_N).cwiseMin(tension_max_N);
  for (int k = 0; k < kGripStringCount; ++k) solution.tension_N[k] = t[k];
  solution.achieved = w * t;
  solution.scale = scale;
  return solution;
}

}  // namespace impetus
