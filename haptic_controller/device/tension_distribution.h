// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tension distribution (docs/architecture.md §1.2 step 6): the force on the finger → four string tensions.
//
// Strings only pull: tension t_i acts along u_i, the unit vector from the finger toward motor i, so the force is A·t
// with A = [u_0 u_1 u_2 u_3]. We solve the box-constrained least-squares problem
//     min |A t − f|² + ε|t|²   subject to  t_min ≤ t_i ≤ t_max,
// whose tiny ε makes it strictly convex (unique answer) and, among the tensions that render f exactly, picks the
// smallest (one string sits at t_min: least motor heat, strings still taut). When f is not reachable the result is
// the nearest reachable force (saturation toward the feasible set), and `saturated` is set.
//
// Method, the usual case first: four strings whose directions surround the finger (every string's "null weight" n_i
// below has the same sign) render any force, and the forces A·t = f form the line t = t_p + λ·n, n the null vector
// of A. The least tension on it within the box has its smallest member at t_min: λ = max_i (t_min − t_p,i)/n_i. If
// that keeps every string at or under t_max it is the answer (exact force; ~40 flops and four square roots).
// Otherwise (a force beyond the motors, or a finger on the rim of the workspace) the general method: the minimiser
// lies on one face of the box; each of the 3⁴ = 81 faces (every string at t_min, at t_max or free) is solved in closed
// form, clamped into the box and scored; the lowest score is the exact optimum, because the true optimum is its own
// face's unclamped solution and every clamped candidate is feasible. Both are fixed work, no iteration that might
// not converge, no allocation. The two agree within the ε bias (tested).

#include "common/spidar/geometry.h"
#include "common/contract/frames.h"

#include <Eigen/Core>

#include <array>

namespace impetus {

struct TensionSolution {
  std::array<double, kStringCount> tension_N{};
  Eigen::Vector3d achieved_force_N = Eigen::Vector3d::Zero();  // A·t: the force the strings actually apply
  bool saturated = false;  // |A t − f| exceeded kSaturationTolerance_N
};

// Force error above which a distribution counts as saturated. The ε bias alone is below 1e-4 N (ε·t_max/σ_min²).
inline constexpr double kSaturationTolerance_N = 1e-3;

// `motors_m` and the finger are in the world frame. A string whose motor coincides with the finger contributes no
// direction. Allocation-free.
TensionSolution distribute_tension(const Eigen::Vector3d& force_N, const Eigen::Vector3d& finger_m,
                                   const std::array<Eigen::Vector3d, kStringCount>& motors_m, double tension_min_N,
                                   double tension_max_N);

// The general method alone (the 81 faces), for tests that compare the two.
TensionSolution distribute_tension_by_faces(const Eigen::Vector3d& force_N, const Eigen::Vector3d& finger_m,
                                            const std::array<Eigen::Vector3d, kStringCount>& motors_m,
                                            double tension_min_N, double tension_max_N);

}  // namespace impetus
