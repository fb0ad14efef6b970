// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/proxy_projection.h"

#include "haptic_controller/gram_solve.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// A constraint violated by less than this is satisfied: far below any physical length (1 pm), far above rounding of
// coordinates of order 1 m (1e-16 m).
constexpr double kFeasibilityTolerance_m = 1e-12;
// A plane whose normal leaves a component smaller than this (the sine of the angle) outside the span of the active
// normals is treated as dependent on them. Two planes 1e-6 rad apart with a 1 µm offset would meet a metre away: such
// an edge is meaningless, so they are one plane.
constexpr double kParallelSine = 1e-6;
// Each iteration adds or drops one constraint; Goldfarb–Idnani terminates in finitely many, typically a handful. This
// bound only guards against cycling from rounding on ties.
constexpr int kMaxIterations = 4 * static_cast<int>(kMaxServoPlanes) + 8;

double slack(const ContactPlane& plane, const Eigen::Vector3d& x) { return plane.normal.dot(x - plane.point_m); }

// Active normals as columns, with the solve of the (well-conditioned, since columns are kept independent) Gram system.
struct ActiveBasis {
  Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
  int size = 0;

  // r = (NᵀN)⁻¹ Nᵀ v (coefficients of the projection of v onto span N).
  Eigen::Vector3d coefficients(const Eigen::Vector3d& v) const {
    return gram_solve(normals, size, normals.transpose() * v);
  }
  Eigen::Vector3d combine(const Eigen::Vector3d& r) const {
    Eigen::Vector3d out = Eigen::Vector3d::Zero();
    for (int j = 0; j < size; ++j) out += r[j] * normals.col(j);
    return out;
  }
};

void rebuild(const PlaneSet& planes, const ProxySolution& s, ActiveBasis& basis) {
  basis.size = s.active_count;
  for (int j = 0; j < s.active_count; ++j) basis.normals.col(j) = planes.planes[s.active[j].plane].normal;
}

void drop(ProxySolution& s, int j) {
  for (int q = j; q + 1 < s.active_count; ++q) s.active[q] = s.active[q + 1];
  --s.active_count;
}

// Whether the plane describes its object at the goal: the goal's offset along the plane from the plane's point is
// within the plane's extent (none: unbounded). Beyond it the object is not there at all (no point of a sphere of
// radius R lies more than R from its tangent point along the tangent plane), and the finger passes beside it.
bool beside_or_on(const ContactPlane& plane, const Eigen::Vector3d& goal) {
  const double within_m = plane.describes_within_m();
  if (!(within_m > 0.0)) return true;
  const Eigen::Vector3d offset = goal - plane.point_m;
  return (offset - offset.dot(plane.normal) * plane.normal).norm() <= within_m;
}

// Whether `x` is where the planes in play (the active ones and p) still describe their objects: within each plane's
// extent of its point, and within the world's reach of the goal (header, "Locally infeasible sets").
bool within_validity(const PlaneSet& planes, const ProxySolution& s, int p, const Eigen::Vector3d& x,
                     const Eigen::Vector3d& goal) {
  // Triangles a mesh walk met are the surface the proxy's way found (ContactPlane::met): among themselves they hold
  // wherever they put it, as the walk did.
  bool all_met = planes.planes[static_cast<std::size_t>(p)].met;
  for (int j = 0; j < s.active_count; ++j) all_met = all_met && planes.planes[s.active[j].plane].met;
  if (all_met) return true;
  if ((x - goal).norm() > planes.valid_within_m) return false;
  auto covers = [&](int k) {
    const ContactPlane& plane = planes.planes[static_cast<std::size_t>(k)];
    const double within_m = plane.describes_within_m();
    return !(within_m > 0.0) || (x - plane.point_m).norm() <= within_m;
  };
  for (int j = 0; j < s.active_count; ++j) {
    if (!covers(s.active[j].plane)) return false;
  }
  return covers(p);
}

// The defined compromise for a conflicting plane (see header).
void settle_infeasible(const PlaneSet& planes, const Eigen::Vector3d& goal, int conflict, ProxySolution& s) {
  const ContactPlane& plane = planes.planes[conflict];
  s.proxy_m += (-0.5 * slack(plane, s.proxy_m)) * plane.normal;
  s.active[s.active_count++] = {conflict, 0.0};
  for (int j = 0; j < s.active_count; ++j) {
    s.active[j].multiplier_m = std::max(0.0, -slack(planes.planes[s.active[j].plane], goal));
  }
  s.infeasible = true;
}

}  // namespace

ProxySolution project_outside_planes(const PlaneSet& planes, const Eigen::Vector3d& goal_m) {
  ProxySolution s;
  s.proxy_m = goal_m;
  ActiveBasis basis;
  const int count = static_cast<int>(planes.count);

  for (int iteration = 0; iteration < kMaxIterations;) {
    // Most violated inactive constraint.
    int p = -1;
    double worst = -kFeasibilityTolerance_m;
    for (int k = 0; k < count; ++k) {
      const double sk = slack(planes.planes[k], s.proxy_m);
      if (sk < worst && beside_or_on(planes.planes[k], goal_m)) {
        bool is_active = false;
        for (int j = 0; j < s.active_count; ++j) is_active = is_active || s.active[j].plane == k;
        if (!is_active) {
          worst = sk;
          p = k;
        }
      }
    }
    if (p < 0) return s;  // feasible and every multiplier ≥ 0: optimal

    const Eigen::Vector3d& np = planes.planes[p].normal;
    double up = 0.0;  // multiplier the new constraint accumulates
    for (; iteration < kMaxIterations; ++iteration) {
      const Eigen::Vector3d r = basis.coefficients(np);
      const Eigen::Vector3d z = np - basis.combine(r);  // primal direction: n_p's part outside the active span
      const bool independent = z.norm() > kParallelSine * np.norm();

      // Dual step limit: the first active multiplier that reaches zero.
      double t_dual = std::numeric_limits<double>::infinity();
      int blocking = -1;
      for (int j = 0; j < s.active_count; ++j) {
        if (r[j] > 0.0 && s.active[j].multiplier_m / r[j] < t_dual) {
          t_dual = s.active[j].multiplier_m / r[j];
          blocking = j;
        }
      }
      // Primal step: the full step that makes p tight.
      const double t_primal =
          independent ? -slack(planes.planes[p], s.proxy_m) / z.squaredNorm() : std::numeric_limits<double>::infinity();

      if (blocking < 0 && !independent) {
        settle_infeasible(planes, goal_m, p, s);
        return s;
      }
      const double t = std::min(t_dual, t_primal);
      if (independent && s.active_count > 0 && !within_validity(planes, s, p, s.proxy_m + t * z, goal_m)) {
        // The proxy would slide along the active planes to where they (or p) no longer describe their objects:
        // nearly opposed faces that overlap (a pinch) cross only δ/sin θ away (0.1 mm at 3e-5 rad is 5 m), and the
        // tangent planes of balls packed around the finger close a pocket whose far corner lies beside the balls,
        // not on them. Sliding there would spring the finger sideways for energy nobody put in.
        settle_infeasible(planes, goal_m, p, s);
        return s;
      }
      if (independent) s.proxy_m += t * z;
      for (int j = 0; j < s.active_count; ++j) s.active[j].multiplier_m -= t * r[j];
      up += t;

      if (independent && t_primal <= t_dual) {
        s.active[s.active_count++] = {p, up};
        rebuild(planes, s, basis);
        ++iteration;
        break;
      }
      drop(s, blocking);
      rebuild(planes, s, basis);
    }
  }
  // Iteration bound reached (rounding ties only): keep the current point, which satisfies the active planes.
  return s;
}

Eigen::Vector3d project_onto_active(const PlaneSet& planes, const ProxySolution& solution, const Eigen::Vector3d& x_m) {
  ActiveBasis basis;
  ProxySolution consistent = solution;
  // When infeasible, the last listed plane is the conflict, dependent on the others: project onto the others only.
  consistent.active_count = std::min(solution.active_count - (solution.infeasible ? 1 : 0), kMaxActiveConstraints);
  rebuild(planes, consistent, basis);
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();  // b − Nᵀx, per active plane
  for (int j = 0; j < basis.size; ++j) residual[j] = -slack(planes.planes[consistent.active[j].plane], x_m);
  // x + N (NᵀN)⁻¹ (b − Nᵀx): with G = NᵀN, the coefficients are G⁻¹·residual.
  return x_m + basis.combine(gram_solve(basis.normals, basis.size, residual));
}

}  // namespace impetus
