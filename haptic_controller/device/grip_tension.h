// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tension distribution for the 8-string grip SPIDAR: a wrench on the grip (force, and torque about its centre) → eight
// string tensions, each between the minimum that keeps the strings taut and the motors' maximum.
//
// The problem: min |t|² subject to W·t = w, t_min ≤ t_k ≤ t_max (W the 6×8 wrench matrix, grip_kinematics.h): the
// wrench exactly, with the least tension (least motor heat; the strings stay taut). Eight strings, six directions:
// the tensions that render w exactly are t = t_p + N·λ, t_p = W⁺·w the least-norm solution and N an orthonormal
// basis of W's two-dimensional null space. Since t_p ⟂ N, |t|² = |t_p|² + |λ|², so the answer is the point nearest the
// origin of the convex polygon in the λ-plane cut by the sixteen limits (t_min ≤ t_p,k + n_k·λ ≤ t_max). The nearest
// point is the origin itself, or the foot of the perpendicular on one of the sixteen lines, or a corner where two
// meet: all 1 + 16 + 120 candidates are tried and the nearest feasible one kept. Fixed work, no iteration that might
// not converge, no allocation.
//
// A wrench beyond the motors (the polygon empty) is scaled down, direction kept, to the largest fraction s of it the
// strings can render (a linear programme in (λ, s), solved exactly over the same corners) and `saturated` set. A pose
// where not even zero wrench is feasible (no tension balance holds the grip: outside the frame's force-closure volume)
// gets every string at t_min and `closure` false.

#include "haptic_controller/device/grip_kinematics.h"

#include <Eigen/Core>

#include <array>

namespace impetus {

struct GripTensionSolution {
  std::array<double, kGripStringCount> tension_N{};
  GripWrench achieved = GripWrench::Zero();  // W·t: what the strings put on the grip
  double scale = 1.0;       // the fraction of the asked wrench rendered
  bool saturated = false;   // scale < 1
  bool closure = true;      // false: no tension balance at this pose (every string at t_min)
};

// Allocation-free.
GripTensionSolution distribute_grip_tension(const GripWrench& wrench, const GripWrenchMatrix& w, double tension_min_N,
                                            double tension_max_N);

}  // namespace impetus
