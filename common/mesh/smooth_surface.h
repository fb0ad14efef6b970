// SPDX-License-Identifier: Apache-2.0
#pragma once
// The smooth surface a closed triangle mesh stands for (docs/meshes.md "A smooth surface"): a scanned pebble or a
// tessellated ball is a curved body cut into facets, and a body that rolls on its facets rolls as a polygon does,
// its contact jumping from vertex to vertex with an impact at each. A mesh object marked `"surface": "smooth"` touches
// the floor with this surface instead (world_manager/engine/smooth_contacts.h).
//
// The surface is Phong tessellation (Boubekeur and Alexa 2008) over the angle-weighted vertex normals: the point of a
// triangle at barycentric b, q = Σ b_i v_i, is moved to q + α Σ b_i ((v_i − q)·n_i) n_i, with α = 1/2, which puts
// the points of a tessellated sphere back on the sphere to fourth order in the facet angle (α = 1 overshoots by the
// facets' sagitta). Over each triangle it is a quadratic patch; the patches meet along the edges, so the surface is
// continuous and passes through every vertex. Its point farthest along a direction is found exactly (the largest of
// a quadratic over a triangle), and it moves continuously as the body turns: a body resting on it rolls without the
// facets' impacts, and the contact does no work on it but where two patches meet at a slight kink, which can only
// take energy away.
//
// Body frame (the mesh's own), metres. Immutable after construction; queries allocate nothing and never throw.

#include "common/mesh/triangle_mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace impetus {

struct SmoothPoint {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the smooth surface
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, outward: the vertex normals interpolated there
  std::uint32_t vertex = 0;                           // the mesh vertex farthest along the direction, near it
};

class SmoothSurface {
 public:
  // A mesh whose edges bend by more than this is not a smooth body's tessellation: 30° is a body 12 triangles around
  // its narrowest circumference, far coarser than a mesh meant as smooth, and below the edges a model means as edges
  // (a cube's 90°, a hexagonal prism's 60°).
  static constexpr double kMaxCrease_rad = 30.0 * 3.14159265358979323846 / 180.0;

  // The mesh should have passed check_mesh as a closed one (every edge between two triangles).
  explicit SmoothSurface(const TriangleMesh& mesh);

  // The point of the surface farthest along `direction` (unit) near vertex `start`: the climb from `start` over the
  // mesh's edges to a vertex no neighbour of which lies farther along `direction`, then the farthest point of the
  // patches over the triangles around it and around its neighbours. On a convex mesh that is the surface's support
  // point wherever the climb starts; on another, the farthest point of the bulge `start` lies on.
  SmoothPoint farthest(const Eigen::Vector3d& direction, std::uint32_t start) const;

  // The largest angle between the normals of two triangles that share an edge, and one of the two triangles.
  double largest_crease_rad() const { return largest_crease_rad_; }
  std::uint32_t largest_crease_triangle() const { return largest_crease_triangle_; }
  // The longest edge: the farthest the surface lies from the facets is far below it.
  double longest_edge_m() const { return longest_edge_m_; }
  std::size_t vertex_count() const { return vertices_m_.size(); }

 private:
  // The largest height along `direction` of the surface over triangle `t`, and where (barycentric, in `b`).
  double farthest_on(std::uint32_t t, const Eigen::Vector3d& direction, Eigen::Vector3d& b) const;
  // The surface's point over triangle `t` at barycentric `b`, with its interpolated normal.
  SmoothPoint point_at(std::uint32_t t, const Eigen::Vector3d& b) const;

  std::vector<Eigen::Vector3d> vertices_m_;
  std::vector<Eigen::Vector3d> normals_;  // unit, angle-weighted
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::vector<std::uint32_t> ring_begin_;     // vertex v's triangles: ring_[ring_begin_[v] .. ring_begin_[v + 1])
  std::vector<std::uint32_t> ring_;
  double largest_crease_rad_ = 0.0;
  std::uint32_t largest_crease_triangle_ = 0;
  double longest_edge_m_ = 0.0;
};

}  // namespace impetus
