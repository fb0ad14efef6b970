// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/press_path.h"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace impetus {

PressStroke stroke_of(const PressMoments& moments) {
  PressStroke stroke;
  if (!moments.all_finite() || !(moments.push_Ns > 0.0)) return stroke;
  const double push_Ns = moments.push_Ns;
  const Eigen::Vector3d centre_m = moments.point_Nsm / push_Ns;
  stroke.push_Ns = push_Ns;
  stroke.from_m = centre_m;
  stroke.to_m = centre_m;
  // C by its definition; rounding can leave it slightly indefinite for a push at one point.
  const Eigen::Matrix3d covariance_m2 = moments.point2_Nsm2 / push_Ns - centre_m * centre_m.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance_m2);
  if (solver.info() != Eigen::Success) return stroke;
  const double largest_m2 = solver.eigenvalues()(2);  // ascending
  // Below a micrometre of spread, a press at one point (a proxy at rest still wanders by rounding).
  constexpr double kMinSpread_m = 1e-6;
  if (!(largest_m2 > kMinSpread_m * kMinSpread_m)) return stroke;
  const Eigen::Vector3d half_m = std::sqrt(3.0 * largest_m2) * solver.eigenvectors().col(2);
  if (!half_m.allFinite()) return stroke;
  stroke.from_m = centre_m - half_m;
  stroke.to_m = centre_m + half_m;
  return stroke;
}

}  // namespace impetus
