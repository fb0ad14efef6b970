// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/tool/contact_qp.h"

#include <Eigen/Cholesky>

#include <cmath>
#include <limits>

namespace impetus {
namespace {

// A contact normal whose part outside the active normals' span is below this fraction of its length lies in that
// span (it depends on them): the method then only shifts load, it does not step. A step along so small a part would
// be the residual over its square, 10¹⁴ times the residual at 10⁻⁷, where the geometry's own rounding (10⁻¹⁶ of a
// length, in normals and levers) has already decided the part's size.
constexpr double kDependent = 1e-7;

}  // namespace

ContactQpResult solve_contact_qp(const std::array<ContactQpRow, kMaxContactRows>& rows, int count,
                                 const Vector6d& metric, const Vector6d& target,
                                 std::array<double, kMaxContactRows>& lambda_N) {
  ContactQpResult result;
  // In y = S·q, S = M^½, the objective is ½|y − y*|² and contact i reads c_iᵀy + gap_i ≥ 0 with c_i = S⁻¹a_i.
  const Vector6d scale = metric.cwiseSqrt();
  std::array<Vector6d, kMaxContactRows> c;
  std::array<bool, kMaxContactRows> in_active{};
  for (int i = 0; i < count; ++i) {
    c[static_cast<std::size_t>(i)] = rows[static_cast<std::size_t>(i)].a.cwiseQuotient(scale);
    lambda_N[static_cast<std::size_t>(i)] = 0.0;
  }
  Vector6d y = scale.cwiseProduct(target);
  const auto residual_m = [&](int i) {
    return c[static_cast<std::size_t>(i)].dot(y) + rows[static_cast<std::size_t>(i)].gap_m;
  };
  std::array<int, 6> active{};
  int active_count = 0;
  const auto active_row = [&](int j) { return static_cast<std::size_t>(active[static_cast<std::size_t>(j)]); };
  const int limit = 4 * count + 12;
  constexpr double kNone = std::numeric_limits<double>::infinity();

  for (;;) {
    // The most violated contact not yet active; none beyond the tolerance: q is the answer.
    int p = -1;
    double worst_m = -kContactQpTolerance_m;
    for (int i = 0; i < count; ++i) {
      if (in_active[static_cast<std::size_t>(i)]) continue;
      const double s_m = residual_m(i);
      if (s_m < worst_m) {
        worst_m = s_m;
        p = i;
      }
    }
    if (p < 0) break;
    const Vector6d& cp = c[static_cast<std::size_t>(p)];
    bool added = false;
    while (!added) {
      if (++result.iterations > limit) {
        result.converged = false;
        break;
      }
      // r = (NᵀN)⁻¹Nᵀc_p: how the active multipliers give way as λ_p grows; z = c_p − N·r: the step in y.
      Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6> normals(6, active_count);
      for (int j = 0; j < active_count; ++j) normals.col(j) = c[active_row(j)];
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> r(active_count);
      if (active_count > 0) {
        const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6> gram = normals.transpose() * normals;
        r = gram.ldlt().solve(normals.transpose() * cp);
      }
      const Vector6d z = cp - normals * r;
      // Partial step: the first active multiplier to reach zero as λ_p grows by t (it leaves the set).
      int leaving = -1;
      double t_partial = kNone;
      for (int j = 0; j < active_count; ++j) {
        if (!(r[j] > 0.0)) continue;
        const double t = lambda_N[active_row(j)] / r[j];
        if (t < t_partial) {
          t_partial = t;
          leaving = j;
        }
      }
      // Full step: contact p closes.
      const double zz = z.squaredNorm();
      // Six independent active contacts span every direction: a seventh depends on them, whatever rounding leaves.
      const bool steps = active_count < 6 && zz > kDependent * kDependent * cp.squaredNorm();
      const double t_full = steps ? -residual_m(p) / zz : kNone;
      const double t = std::min(t_partial, t_full);
      if (!(t < kNone)) {  // p depends on the active contacts and none can give way: no q satisfies them all
        result.converged = false;
        break;
      }
      for (int j = 0; j < active_count; ++j) lambda_N[active_row(j)] -= t * r[j];
      lambda_N[static_cast<std::size_t>(p)] += t;
      if (steps) y += t * z;
      if (t_full <= t_partial) {
        active[static_cast<std::size_t>(active_count++)] = p;
        in_active[static_cast<std::size_t>(p)] = true;
        added = true;
      } else {
        const int k = active[static_cast<std::size_t>(leaving)];
        lambda_N[static_cast<std::size_t>(k)] = 0.0;
        in_active[static_cast<std::size_t>(k)] = false;
        active[static_cast<std::size_t>(leaving)] = active[static_cast<std::size_t>(--active_count)];
      }
    }
    if (!result.converged) break;
  }
  result.q = y.cwiseQuotient(scale);
  for (int i = 0; i < count; ++i) result.active += lambda_N[static_cast<std::size_t>(i)] > 0.0 ? 1 : 0;
  return result;
}

}  // namespace impetus
