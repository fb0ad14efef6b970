// SPDX-License-Identifier: Apache-2.0
// Pieces the kinds' files share.
#include "common/shape/shape_kind.h"

#include "common/contract/limits.h"
#include "common/runtime/json_node.h"

#include <cmath>

namespace impetus::shape_detail {

SurfacePoint nearest_on_sphere(const Eigen::Vector3d& centre_m, double radius_m, const Eigen::Vector3d& query_m,
                               const Eigen::Vector3d& fallback_normal) {
  const Eigen::Vector3d offset_m = query_m - centre_m;
  const double distance_m = offset_m.norm();
  const Eigen::Vector3d normal = distance_m > kDegenerateDistance_m ? Eigen::Vector3d(offset_m / distance_m)
                                                                    : fallback_normal;
  return {centre_m + radius_m * normal, normal, distance_m - radius_m};
}

void retake_about_centre(ShapePlane& plane, const Eigen::Vector3d& centre_m, double radius_m,
                         const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d offset_m = around_m - centre_m;
  const double distance_m = offset_m.norm();
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) return;
  plane.normal = offset_m / distance_m;
  plane.point_m = centre_m + radius_m * plane.normal;
}

bool clip_slab(double from, double delta, double half, double& t0, double& t1) {
  if (!(half > 0.0)) return false;  // shrunk past its middle: no slab left
  if (std::abs(delta) < 1e-300) return std::abs(from) < half;
  double ta = (-half - from) / delta, tb = (half - from) / delta;
  if (ta > tb) std::swap(ta, tb);
  t0 = std::max(t0, ta);
  t1 = std::min(t1, tb);
  return t0 < t1;
}

double parse_length(const JsonNode& value, bool may_be_zero) {
  return value.in_range(may_be_zero ? 0.0 : limits::kMinLength_m, limits::kMaxLength_m, " m");
}

bool length_ok(double length_m, bool may_be_zero) {
  return std::isfinite(length_m) && length_m >= (may_be_zero ? 0.0 : limits::kMinLength_m) &&
         length_m <= limits::kMaxLength_m;
}

}  // namespace impetus::shape_detail
