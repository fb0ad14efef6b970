// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/grip_kinematics.h"

#include "common/contract/rotation.h"

#include <Eigen/Cholesky>

#include <cmath>

namespace impetus {
namespace {

bool finite(const GripLengths& lengths) {
  for (double l : lengths) {
    if (!std::isfinite(l)) return false;
  }
  return true;
}

// Residuals r_k = |motor_k − (p + R·a_k)| − length_k, and their sum of squares.
double residuals(const GripStrings& strings, const GripPose& pose, const GripLengths& lengths,
                 Eigen::Matrix<double, kGripStringCount, 1>& r) {
  const Eigen::Matrix3d rotation = pose.orientation.toRotationMatrix();
  for (int k = 0; k < kGripStringCount; ++k) {
    r[k] = (strings.motor_m(k) - pose.position_m - rotation * strings.attachment_m(k)).norm() - lengths[k];
  }
  return r.squaredNorm();
}

// The pose moved by δ = (δp, δθ): p + δp, and R turned by δθ (world frame) first.
GripPose moved(const GripPose& pose, const Eigen::Matrix<double, 6, 1>& step) {
  GripPose next;
  next.position_m = pose.position_m + step.head<3>();
  next.orientation = turned(pose.orientation, step.tail<3>());
  return next;
}

}  // namespace

const char* to_string(GripSolveStatus status) {
  switch (status) {
    case GripSolveStatus::ok: return "ok";
    case GripSolveStatus::not_finite: return "a length or the guess is not finite";
    case GripSolveStatus::singular: return "the strings do not fix the grip's pose here";
    case GripSolveStatus::not_converged: return "the pose did not converge";
    case GripSolveStatus::inconsistent: return "the lengths fit no rigid pose (a slack or slipped string)";
  }
  return "unknown";
}

GripSolve GripKinematics::pose(const GripLengths& lengths, const GripPose& guess, GripPose& out) const {
  GripSolve solve;
  out = guess;
  if (!finite(lengths) || !guess.position_m.allFinite() || !guess.orientation.coeffs().allFinite()) {
    solve.status = GripSolveStatus::not_finite;
    return solve;
  }
  out.orientation.normalize();
  Eigen::Matrix<double, kGripStringCount, 1> r;
  double cost = residuals(*this, out, lengths, r);
  // The grip radius turns an angle into a length, so one tolerance serves both parts of a step.
  const double radius_m = std::max(geometry().grip_radius_m, 1e-3);
  bool converged = false;
  for (solve.iterations = 0; solve.iterations < kMaxIterations && !converged; ++solve.iterations) {
    // Gauss–Newton with J = −Wᵀ: (W·Wᵀ)·δ = W·r.
    const GripWrenchMatrix w = wrench_matrix(out);
    const Eigen::Matrix<double, 6, 6> normal = w * w.transpose();
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> factor(normal);
    // Singular: the smallest pivot is a vanishing fraction of the largest (an orientation or position the lengths
    // do not change to first order).
    const auto pivots = factor.vectorD();
    if (factor.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) {
      solve.status = GripSolveStatus::singular;
      solve.residual_rms_m = std::sqrt(cost / kGripStringCount);
      return solve;
    }
    Eigen::Matrix<double, 6, 1> step = factor.solve(w * r);
    // Halve the step until it lowers the residual (far from the answer a full step can overshoot).
    bool lowered = false;
    for (int halving = 0; halving < 20 && !lowered; ++halving) {
      const GripPose next = moved(out, step);
      Eigen::Matrix<double, kGripStringCount, 1> next_r;
      const double next_cost = residuals(*this, next, lengths, next_r);
      if (next_cost <= cost) {
        lowered = true;
        out = next;
        r = next_r;
        cost = next_cost;
      } else {
        step *= 0.5;
      }
    }
    // Done when the step is below a count by far, or when no step along the Gauss–Newton direction lowers the
    // residual: at the least-squares answer to rounding, or stuck far from it, which the residual test below tells.
    const double moved_m = std::max(step.head<3>().norm(), radius_m * step.tail<3>().norm());
    converged = !lowered || moved_m < kStepTolerance_m;
  }
  solve.residual_rms_m = std::sqrt(cost / kGripStringCount);
  if (!converged) {
    solve.status = GripSolveStatus::not_converged;
  } else if (solve.residual_rms_m > kInconsistentCounts * geometry().metres_per_count) {
    solve.status = GripSolveStatus::inconsistent;
  }
  return solve;
}

}  // namespace impetus
