// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/smooth_floor.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {

int SmoothFloor::touches(const Eigen::Vector3d& com_m, const Eigen::Matrix3d& rotation, double floor_z_m,
                         std::span<const Eigen::Vector3d> facet_contacts_m, std::span<FloorTouch> out) {
  const Eigen::Vector3d down = rotation.transpose() * -Eigen::Vector3d::UnitZ();  // body frame
  // A place is kept for the next step while the surface there is within an edge of the floor: farther, the facets'
  // vertices reach the floor before the surface between them does, and the engine's contacts find it again.
  const double keep_within_m = surface_.longest_edge_m();
  std::array<std::uint32_t, kMaxPlaces> found{};
  int found_count = 0;
  std::uint32_t deepest_vertex = 0;
  double deepest_m = -std::numeric_limits<double>::infinity();
  int count = 0;
  const auto visit = [&](std::uint32_t start) {
    const SmoothPoint lowest = surface_.farthest(down, start);
    if (std::find(found.begin(), found.begin() + found_count, lowest.vertex) != found.begin() + found_count) return;
    const Eigen::Vector3d point_m = com_m + rotation * lowest.point_m;
    const double depth_m = floor_z_m - point_m.z();
    if (depth_m > deepest_m) {
      deepest_m = depth_m;
      deepest_vertex = lowest.vertex;
    }
    if (depth_m > -keep_within_m && found_count < kMaxPlaces) {
      found[static_cast<std::size_t>(found_count++)] = lowest.vertex;
    }
    if (depth_m >= 0.0 && count < static_cast<int>(out.size())) {
      out[static_cast<std::size_t>(count++)] = {point_m, depth_m};
    }
  };
  for (int i = 0; i < place_count_; ++i) visit(places_[static_cast<std::size_t>(i)]);
  for (const Eigen::Vector3d& contact_m : facet_contacts_m) {
    // From the lowest vertex of the triangle nearest where the facets touch.
    MeshPoint nearest;
    if (!body_.bvh().nearest(rotation.transpose() * (contact_m - com_m), nearest)) continue;
    const auto& tri = body_.bvh().mesh().triangles[nearest.triangle];
    const auto& vertices = body_.bvh().mesh().vertices_m;
    std::uint32_t start = tri[0];
    for (std::uint32_t v : tri) {
      if (down.dot(vertices[v]) > down.dot(vertices[start])) start = v;
    }
    visit(start);
  }
  // And from vertices spread over the whole mesh, so that every bulge that reaches down has a climb ending on it, even
  // where the engine's few contacts a pair all lie at another.
  const auto vertices = static_cast<std::uint32_t>(surface_.vertex_count());
  for (std::uint32_t k = 0; k < kProbes; ++k) visit(static_cast<std::uint32_t>(std::uint64_t{k} * vertices / kProbes));
  // Nothing within reach: the deepest place is still the best start for the next climb.
  if (found_count == 0 && deepest_m > -std::numeric_limits<double>::infinity()) found[found_count++] = deepest_vertex;
  places_ = found;
  place_count_ = found_count;
  // Every facet contact within a place's footprint, or the body lies along the floor there.
  const double bounding_m = body_.shape().radius_m;
  for (const Eigen::Vector3d& contact_m : facet_contacts_m) {
    bool near_place = false;
    for (int i = 0; i < count && !near_place; ++i) {
      const FloorTouch& touch = out[static_cast<std::size_t>(i)];
      const double footprint_m = std::sqrt(2.0 * bounding_m * touch.depth_m) + 2.0 * keep_within_m;
      near_place = (contact_m - touch.point_m).head<2>().norm() <= footprint_m;
    }
    if (!near_place) return kUseFacets;
  }
  return count;
}

}  // namespace impetus
