// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/sphere_planes.h"

#include <cmath>

namespace impetus {

void retake_sphere_planes(PlaneSet& planes, const Eigen::Vector3d& around_m) {
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (!plane.sphere()) continue;
    const Eigen::Vector3d centre_m = plane.point_m - plane.extent_m * plane.normal;
    const Eigen::Vector3d offset_m = around_m - centre_m;
    const double distance_m = offset_m.norm();
    if (!(distance_m > 0.0) || !std::isfinite(distance_m)) continue;
    plane.normal = offset_m / distance_m;
    plane.point_m = centre_m + plane.extent_m * plane.normal;
  }
}

}  // namespace impetus
