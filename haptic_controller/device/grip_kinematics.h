// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 8-string grip SPIDAR's forward kinematics (common/spidar/grip_geometry.h): the grip's pose from its eight string
// lengths. What the strings do at a pose (lengths, counts, the wrench matrix W) is common/spidar/grip_strings.h, shared
// with the simulated hardware.
//
// Forward kinematics (lengths → pose) has no closed form for eight strings on a body that turns; it is solved by
// Gauss–Newton on the eight lengths from a guess (the last pose: at 1 kHz the grip moves micrometres a tick, and one
// or two iterations converge), with step halving when a step does not lower the residual. Its Jacobian is −Wᵀ, W the
// wrench matrix below: a string's length changes with the grip's motion exactly as its pull does work on it.

#include "common/spidar/grip_strings.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>

namespace impetus {

enum class GripSolveStatus {
  ok,
  not_finite,     // a length or the guess is not finite
  singular,       // the strings do not fix the pose here (W·Wᵀ nearly singular): a grip at the frame's edge
  not_converged,  // no step lowered the residual before the iteration limit
  inconsistent,   // converged, but the lengths disagree with any rigid pose by more than a few counts
};
const char* to_string(GripSolveStatus status);

struct GripSolve {
  GripSolveStatus status = GripSolveStatus::ok;
  int iterations = 0;
  double residual_rms_m = 0.0;  // √(mean over the strings of (|motor − attachment| − length)²) at the answer
};

// The pose from the lengths, on top of what the strings do at a pose (common/spidar/grip_strings.h).
class GripKinematics : public GripStrings {
 public:
  // Gauss–Newton's limits. A warm start converges in 1–3 iterations, a cold one from the frame's centre within 10
  // for poses across the working volume (tested); 30 leaves room and bounds a tick's worst case.
  static constexpr int kMaxIterations = 30;
  // Converged when a step moves the grip less than this (m, and rad times the grip radius): far below a count.
  static constexpr double kStepTolerance_m = 1e-10;

  explicit GripKinematics(const SpidarGripGeometry& geometry) : GripStrings(geometry) {}

  // Forward kinematics from `guess`: `out` gets the pose whatever the status (the last iterate), and the status says
  // whether to trust it. Inconsistent means a residual above kInconsistentCounts counts RMS: quantisation leaves at
  // most half a count a string, so more is a slack, stretched or slipped string. Allocation-free.
  static constexpr double kInconsistentCounts = 4.0;
  GripSolve pose(const GripLengths& lengths_m, const GripPose& guess, GripPose& out) const;
};

}  // namespace impetus
