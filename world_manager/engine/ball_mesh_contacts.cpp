// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/ball_mesh_contacts.h"

#include <array>

namespace impetus {

int ball_mesh_contacts(const Eigen::Vector3d& centre_m, double radius_m, const MeshBody& body,
                       const Eigen::Vector3d& com_m, const Eigen::Matrix3d& rotation, std::span<BallContact> out) {
  const Eigen::Vector3d centre_body = rotation.transpose() * (centre_m - com_m);
  std::array<MeshPoint, 32> near;  // more than a ball rests on; the nearest kept if more come within the radius
  const int found = body.bvh().within(centre_body, radius_m, near);
  int count = 0;
  for (int i = 0; i < found && count < static_cast<int>(out.size()); ++i) {
    const MeshPoint& point = near[static_cast<std::size_t>(i)];
    const Eigen::Vector3d away = centre_body - point.point_m;
    const double distance_m = away.norm();
    // From the surface toward the centre; behind the surface (or on it), the feature's outward pseudo-normal.
    const Eigen::Vector3d normal_body =
        point.signed_distance_m > 0.0 && distance_m > 0.0 ? Eigen::Vector3d(away / distance_m) : point.normal;
    const double depth_m = point.signed_distance_m > 0.0 ? radius_m - distance_m : radius_m + distance_m;
    const Eigen::Vector3d point_m = com_m + rotation * point.point_m;
    const Eigen::Vector3d normal = rotation * normal_body;
    bool own_place = true;  // in front of every nearer contact's tangent plane
    for (int k = 0; k < count && own_place; ++k) {
      const BallContact& kept = out[static_cast<std::size_t>(k)];
      own_place = kept.normal.dot(point_m - kept.point_m) > kOnSurface_m;
    }
    if (!own_place) continue;
    out[static_cast<std::size_t>(count++)] = {point_m, normal, depth_m};
  }
  return count;
}

}  // namespace impetus
