// SPDX-License-Identifier: Apache-2.0
#pragma once
// Kinematics of the 8-string grip SPIDAR (common/spidar/grip_geometry.h): the grip's pose ↔ eight string lengths, and
// the wrench matrix that maps string tensions to the force and torque on the grip.
//
// Frames and units: world frame, z up, SI. A pose is the grip's centre and its orientation (grip → world). Encoder
// counts are absolute string lengths, length = count · metres_per_count, as for the 4-string device.
//
// Forward kinematics (lengths → pose) has no closed form for eight strings on a body that turns; it is solved by
// Gauss–Newton on the eight lengths from a guess (the last pose: at 1 kHz the grip moves micrometres a tick, and one
// or two iterations converge), with step halving when a step does not lower the residual. Its Jacobian is −Wᵀ, W the
// wrench matrix below: a string's length changes with the grip's motion exactly as its pull does work on it.

#include "common/spidar/grip_geometry.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>

namespace impetus {

struct GripPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();               // the grip's centre, world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();    // grip → world, unit
};

using GripLengths = std::array<double, kGripStringCount>;
using GripCounts = std::array<std::int64_t, kGripStringCount>;
// Column k: [u_k; (R·a_k) × u_k], u_k the unit vector from string k's attachment toward its motor. W·t is the force
// (N) and the torque about the grip's centre (N·m) that tensions t (N) put on the grip, world frame.
using GripWrenchMatrix = Eigen::Matrix<double, 6, kGripStringCount>;

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

class GripKinematics {
 public:
  // Gauss–Newton's limits. A warm start converges in 1–3 iterations, a cold one from the frame's centre within 10
  // for poses across the working volume (tested); 30 leaves room and bounds a tick's worst case.
  static constexpr int kMaxIterations = 30;
  // Converged when a step moves the grip less than this (m, and rad times the grip radius): far below a count.
  static constexpr double kStepTolerance_m = 1e-10;

  explicit GripKinematics(const SpidarGripGeometry& geometry);

  const SpidarGripGeometry& geometry() const { return geometry_; }
  const Eigen::Vector3d& motor_m(int k) const { return motors_m_[k]; }

  // Inverse kinematics: the exact lengths at a pose, and the counts a device would report (nearest count).
  GripLengths lengths_m(const GripPose& pose) const;
  GripCounts encoder_counts(const GripPose& pose) const;
  GripLengths lengths_m(const GripCounts& counts) const;

  // Forward kinematics from `guess`: `out` gets the pose whatever the status (the last iterate), and the status says
  // whether to trust it. Inconsistent means a residual above kInconsistentCounts counts RMS: quantisation leaves at
  // most half a count a string, so more is a slack, stretched or slipped string. Allocation-free.
  static constexpr double kInconsistentCounts = 4.0;
  GripSolve pose(const GripLengths& lengths_m, const GripPose& guess, GripPose& out) const;

  GripWrenchMatrix wrench_matrix(const GripPose& pose) const;

 private:
  SpidarGripGeometry geometry_;
  std::array<Eigen::Vector3d, kGripStringCount> motors_m_;
  std::array<Eigen::Vector3d, kGripStringCount> attachments_m_;  // grip frame
};

}  // namespace impetus
