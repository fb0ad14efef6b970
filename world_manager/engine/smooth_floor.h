// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a mesh body marked `"surface": "smooth"` touches the floor (docs/meshes.md "A smooth surface"): at the points
// of its smooth surface (common/mesh/smooth_surface.h) farthest below, not at its facets' vertices. A tessellated
// ball on its facets rolls as a polygon, with an impact at each vertex; on its smooth surface the contact moves
// continuously as it turns, and it rolls as a ball does.
//
// Each place the body may touch is found by a climb over the mesh's vertices to the lowest one near it, started from
// where the facets touch (the engine's own contacts, which find every place a vertex is below the floor) and from the
// places found in earlier steps (where the smooth surface bulges below the floor between vertices that are not). A
// convex body has one such place; a banana lying on the floor, two.
//
// A place is a point: it holds a body where the surface is curved. A body that lies along the floor (a torus flat on
// it, a pebble on a flat side) touches it over a ring or a patch, which no set of lowest points holds level. Where the
// facets touch the floor outside every place's footprint (the circle a ball of the body's bounding radius pressed as
// deep would make, widened by two edges), the facets' own contacts are kept instead.
//
// Engine-neutral: the engine gives the body's pose and the facets' contacts, and turns what this returns into its own
// contacts. One per smooth body; not thread-safe (the engine's step is one thread). World frame, SI units.

#include "common/mesh/mesh_body.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>

namespace impetus {

struct FloorTouch {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the smooth surface, below the floor (or on it)
  double depth_m = 0.0;                               // how far below the floor, ≥ 0
};

class SmoothFloor {
 public:
  // Places remembered from step to step: more than a resting body of any useful shape touches the floor at.
  static constexpr int kMaxPlaces = 8;
  // Climbs started from vertices spread over the mesh, each call: twice the places, so that the basins of the lowest
  // bulges of a body with a few (a peanut's two, a stool's three legs) each get some.
  static constexpr std::uint32_t kProbes = 2 * kMaxPlaces;

  explicit SmoothFloor(const MeshBody& body) : body_(body), surface_(body.smooth_surface()) {}

  // The touches of the body at `com_m` turned by `rotation` (body → world) with the floor z = `floor_z_m`, given the
  // points `facet_contacts_m` where its facets touch it (may be none). At most `out.size()`; returns how many, or
  // kUseFacets when the facets' contacts are to stand.
  static constexpr int kUseFacets = -1;
  int touches(const Eigen::Vector3d& com_m, const Eigen::Matrix3d& rotation, double floor_z_m,
              std::span<const Eigen::Vector3d> facet_contacts_m, std::span<FloorTouch> out);

  // How far the smooth surface may lie below the facets' lowest vertex: less than its longest edge.
  double reach_m() const { return surface_.longest_edge_m(); }

 private:
  const MeshBody& body_;
  const SmoothSurface& surface_;
  std::array<std::uint32_t, kMaxPlaces> places_{};  // lowest vertices found, the last step's first
  int place_count_ = 0;
};

}  // namespace impetus
