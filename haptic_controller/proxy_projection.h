// SPDX-License-Identifier: Apache-2.0
#pragma once
// The constrained step of the god-object (Zilles & Salisbury; paper §3.3): the point closest to a goal that lies
// outside every plane, i.e. min |x − goal|² subject to n_k·(x − p_k) ≥ 0 for all k.
//
// Every plane is a half-space, so the free space is their intersection, a convex polyhedron, and Zilles & Salisbury's
// walk from a feasible previous proxy toward the finger (stop at the first plane crossed, slide on it, add planes up to
// an edge or a corner) ends at the Euclidean projection of the goal onto it. We compute that projection directly with
// the dual active-set method of Goldfarb & Idnani (1983) specialised to the identity Hessian. It needs no feasible
// start, so planes that moved over the previous proxy push it out, and it returns the Lagrange multipliers:
//     x − goal = Σ_active λ_k n_k,  λ_k ≥ 0,  n_k·(x − p_k) = 0 on active planes,
// λ_k in metres (the depth the constraint holds the goal back), used to share the reaction among objects.
//
// Degenerate sets:
//  * At most three planes are active (3 independent normals fix a point: a corner; 2 an edge line; 1 a face).
//  * Duplicate, parallel and nearly parallel planes (normals within kParallelSine, e.g. 1e-9 rad): a plane whose
//    normal is (numerically) a combination of the active ones is never added as a separate constraint; the dual step
//    swaps it for the active plane it makes redundant, so the more restrictive of two near-parallel planes wins
//    ("treated as one").
//  * Infeasible sets (no point is outside all planes, e.g. a finger pinched between two objects whose planes face
//    each other and overlap): the solver stops at the first conflicting plane and places the proxy at the compromise
//    that splits the conflict in half (moved along that plane's normal by half its violation, e.g. the midpoint of
//    two overlapping opposite planes). `infeasible` is set; the conflicting plane is listed as a fourth (or further)
//    active constraint, and multipliers become the depth of the goal behind each listed plane, so the reaction still
//    goes to the objects that pinch. Always finite for finite input.
//  * Planes that do not reach the goal: a plane whose extent (describes_within_m, > 0) is less than the goal's offset
//    along it from the plane's point describes an object that is not there (the finger is beside a ball, not over its
//    tangent plane's far reaches) and does not constrain the proxy. Without this a ball 3 cm above the finger pressed
//    it through its infinite tangent plane, at a lever that spun the 3 g ball to 1200 rad/s.
//  * Locally infeasible sets: nearly opposed planes that overlap do meet, but δ/sin θ along their wedge, and tangent
//    planes of balls packed around the finger close a pocket whose corners lie beside the balls. A plane is §3.1's
//    first-order picture of its object near its point: it holds within its extent (common/shape/shape.h
//    describes_within_m: a sphere's radius, a box's diagonal, a long body's bounding diagonal), and the plane set as
//    a whole within planes.valid_within_m of the goal (the world's reach: it sent nothing beyond). Once the proxy has
//    left the finger's spot (an edge or corner is being built), a step that takes it beyond either treats the plane
//    being added as conflicting with the active ones, exactly as an opposite parallel plane: same compromise, same
//    flag. A single plane is never bounded: however deep the finger, its proxy is the projection onto that face. Nor
//    are the triangles a mesh walk met (ContactPlane::met): they are the surface itself, found along the proxy's way.

#include "haptic_controller/contact_plane.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>

namespace impetus {

inline constexpr int kMaxActiveConstraints = 3;

struct ActiveConstraint {
  int plane = -1;             // index into the PlaneSet
  double multiplier_m = 0.0;  // λ ≥ 0
};

struct ProxySolution {
  Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();
  std::array<ActiveConstraint, kMaxActiveConstraints + 1> active{};  // the +1 holds the conflict when infeasible
  int active_count = 0;
  bool infeasible = false;
};

// Allocation-free; bounded iterations.
ProxySolution project_outside_planes(const PlaneSet& planes, const Eigen::Vector3d& goal_m);

// Constraints listed in `solution` (active_count, a pinch's conflicting plane included), bounded by the array.
inline int listed_constraints(const ProxySolution& solution) {
  return solution.active_count < 0 ? 0 : std::min(solution.active_count, kMaxActiveConstraints + 1);
}

// The share of the load that listed constraint j carries: its multiplier over their sum, or an equal share when none
// carries any (touching, not pressing). What the reaction and the objects' give are weighted by (§3.4).
inline double load_share(const ProxySolution& solution, int j) {
  const int listed = listed_constraints(solution);
  double sum = 0.0;
  for (int q = 0; q < listed; ++q) sum += solution.active[q].multiplier_m;
  return sum > 0.0 ? solution.active[j].multiplier_m / sum : 1.0 / listed;
}

// Projection of `x` onto the intersection of the active planes' boundaries (a face, edge line or corner point).
Eigen::Vector3d project_onto_active(const PlaneSet& planes, const ProxySolution& solution, const Eigen::Vector3d& x_m);

}  // namespace impetus
