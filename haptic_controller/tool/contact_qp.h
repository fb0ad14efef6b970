// SPDX-License-Identifier: Apache-2.0
#pragma once
// The tool proxy's move (tool_proxy.h): the 6-vector q nearest a target q* in a diagonal metric M, outside every
// linearised contact,
//     minimise ½(q − q*)ᵀM(q − q*)   subject to   a_iᵀq + gap_i ≥ 0,  i = 1…n,
// with the contacts' multipliers λ_i ≥ 0 (M(q − q*) = Σ λ_i·a_i, λ_i = 0 where a contact is open).
//
// Solved exactly by Goldfarb & Idnani's dual active-set method (Math. Programming 27, 1983) in the scaled variable
// y = M^½·q, where the objective is the distance to y*: from the unconstrained optimum it adds the most violated
// contact, steps along the part of its normal the active ones leave free, and drops an active contact whose
// multiplier would turn negative. At most six contacts are active, with independent normals: where several are
// redundant (a face flat on a face touches at four corners and more) the one the method meets first carries the load,
// and the wrench Σ λ_i·a_i, which is unique, is exact. A projected Gauss–Seidel (the first version) crawled on such
// redundant rows: 200 sweeps left 3·10⁻⁶ N·m of torque on a cube pressed flat.
//
// Allocation-free; q = 0 must be feasible (every gap ≥ 0), which bounds the answer: |q|_M ≤ |q*|_M.

#include <Eigen/Core>

#include <array>

namespace impetus {

inline constexpr int kMaxContactRows = 96;

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct ContactQpRow {
  Vector6d a = Vector6d::Zero();
  double gap_m = 0.0;  // ≥ 0
};

struct ContactQpResult {
  Vector6d q = Vector6d::Zero();
  int active = 0;           // contacts with λ > 0
  int iterations = 0;       // contacts added and dropped
  bool converged = true;    // every contact holds to kContactQpTolerance_m within the iteration limit
};

// A contact that holds to within this (m, a_iᵀq + gap_i ≥ −tolerance) is kept.
inline constexpr double kContactQpTolerance_m = 1e-12;

// Solves the problem for rows[0, count); writes λ_i to lambda_N[i] (0 for an open contact). `metric` is M's
// diagonal (all > 0).
ContactQpResult solve_contact_qp(const std::array<ContactQpRow, kMaxContactRows>& rows, int count,
                                 const Vector6d& metric, const Vector6d& target,
                                 std::array<double, kMaxContactRows>& lambda_N);

}  // namespace impetus
