// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/press_path.h"

#include <cmath>

namespace impetus {

PressStroke stroke_of(const PressMoments& moments) {
  PressStroke stroke;
  if (!moments.all_finite() || !(moments.push_Ns > 0.0)) return stroke;
  const double push_Ns = moments.push_Ns;
  const Eigen::Vector3d centre_m = moments.point_Nsm / push_Ns;
  const double mean_time_s = moments.time_Nss / push_Ns;
  // σ² by its definition; rounding can leave it slightly negative for a push within one tick.
  const double variance_s2 = moments.time2_Nsss / push_Ns - mean_time_s * mean_time_s;
  stroke.push_Ns = push_Ns;
  stroke.from_m = centre_m;
  stroke.to_m = centre_m;
  // Below a microsecond of spread, rounding of t̄² (session times of minutes) dominates σ²: a press at one instant.
  constexpr double kMinSpread_s = 1e-6;
  if (!(variance_s2 > kMinSpread_s * kMinSpread_s)) return stroke;
  const Eigen::Vector3d velocity_mps = (moments.point_time_Nssm / push_Ns - centre_m * mean_time_s) / variance_s2;
  const Eigen::Vector3d half_m = velocity_mps * std::sqrt(3.0 * variance_s2);
  if (!half_m.allFinite()) return stroke;
  stroke.from_m = centre_m - half_m;
  stroke.to_m = centre_m + half_m;
  return stroke;
}

}  // namespace impetus
