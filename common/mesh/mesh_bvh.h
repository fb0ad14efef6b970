// SPDX-License-Identifier: Apache-2.0
#pragma once
// Nearest points on a triangle mesh, fast enough for the 1 kHz servo (docs/meshes.md): a bounding-volume hierarchy of
// axis-aligned boxes over the triangles, built once, and a query that walks it nearest box first and skips every box
// farther than the best point so far.
//
// Inside or outside: the sign of a query's distance comes from the angle-weighted pseudo-normal of the feature its
// nearest point lies on (the triangle's normal in a face's interior, the sum of the two faces' normals on an edge,
// the angle-weighted sum of the faces around a vertex; Bærentzen and Aanæs 2005), which is exact for a closed mesh,
// also at edges and corners where a face normal would give the wrong side.
//
// The query allocates nothing and never throws; the tree holds the mesh's copy and is immutable after construction,
// so any number of threads may query it.

#include "common/mesh/huge_pages.h"
#include "common/mesh/triangle_mesh.h"
#include "common/shape/mesh_geometry.h"  // MeshEntry

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <span>
#include <cstdint>
#include <vector>

namespace impetus {

struct MeshPoint {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the mesh
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, outward: the feature's pseudo-normal
  double signed_distance_m = 0.0;                     // positive outside (along the normal), negative inside
  std::uint32_t triangle = 0;
  // Where on the triangle: 0 its interior, 1–3 the edges ab, bc, ca, 4–6 the vertices a, b, c.
  std::uint8_t feature = 0;
};

class MeshBvh {
 public:
  // Builds the tree: O(n log n); the mesh should have passed check_mesh (degenerate triangles have no normal).
  explicit MeshBvh(TriangleMesh mesh);

  // The point of the mesh nearest `query_m` (mesh frame). False only for an empty mesh.
  bool nearest(const Eigen::Vector3d& query_m, MeshPoint& out) const;
  // The same, but only if it lies within `max_distance_m`: a finger out of reach costs a few box tests.
  bool nearest_within(const Eigen::Vector3d& query_m, double max_distance_m, MeshPoint& out) const;
  // The same answer as nearest(), started from the triangle of `hint` (the last tick's answer): a point that moved
  // little since has its nearest point on or beside that triangle, so the walk skips nearly every box at once.
  bool nearest_from(const Eigen::Vector3d& query_m, const MeshPoint& hint, MeshPoint& out) const;

  // The points of the mesh within `radius_m` of `query_m`, one per triangle that comes that near (its nearest point,
  // with the pseudo-normal of the feature it lies on and the side, as nearest() gives them), nearest first, at most
  // `out.size()` of them (the nearest). Returns how many. What a ball touching the mesh touches.
  int within(const Eigen::Vector3d& query_m, double radius_m, std::span<MeshPoint> out) const;

  // Whether the segment from `a` to `b` crosses a triangle at a parameter t in (t_min, 1] (t = 0 at `a`): the
  // triangle's plane between its two ends, within its edges (Möller and Trumbore's test). Both sides count.
  bool segment_crosses(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t_min) const;
  // The first triangle whose outer side the way from `a` to `b` goes in through: `a` in front of its plane or at most
  // `tolerance_m` behind it (on it, to rounding), `b` behind it by more than `tolerance_m`, and the crossing within
  // `tolerance_m` of the triangle (so a way cannot slip between two triangles through their shared edge). The least
  // t wins; triangles in `skip` are not tried. A way along a triangle's plane, or out of it, does not go in.
  bool first_entry(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance_m,
                   const std::uint32_t* skip, int skip_count, MeshEntry& out) const;

  // Whether `x` lies on triangle `triangle`: within `tolerance_m` of its plane, and inside its edges or less than
  // `tolerance_m` outside one (first_entry's test for where a way crosses). `out` is then the foot of `x` on the
  // plane, with the triangle's normal and t = 0. False for an index out of range.
  bool on_triangle(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m, MeshEntry& out) const;

  // Whether every edge joins two triangles at a convex bend (or flat): a closed mesh that is, is a convex body.
  bool locally_convex() const { return locally_convex_; }

  const TriangleMesh& mesh() const { return mesh_; }
  const Eigen::AlignedBox3d& bounds() const { return nodes_.front().bounds; }
  std::size_t node_count() const { return nodes_.size(); }
  // Bytes the tree and its mesh hold (for docs/meshes.md's memory per triangle).
  std::size_t memory_bytes() const;

 private:
  struct Node {
    Eigen::AlignedBox3d bounds;
    std::uint32_t first = 0;  // leaf: first index into order_; inner: the right child (the left is the next node)
    std::uint32_t count = 0;  // leaf: triangles; inner: 0
  };
  // The tree again, each node folded with its children into one of four (a node's grandchildren where its child is
  // not a leaf): half the levels, and a node's four boxes tested together, lane by lane (the test that takes more than
  // half of a mesh tick, docs/meshes.md). Its boxes are floats rounded outward: they only prune, the triangles are
  // tested exactly, so first_entry, which walks it, answers as the binary tree would.
  struct alignas(64) WideNode {
    std::array<float, 4> min_x, min_y, min_z, max_x, max_y, max_z;
    std::array<std::uint32_t, 4> child;  // a leaf's first index into order_, or a wide node
    std::array<std::uint32_t, 4> count;  // a leaf's triangles; kInner for a wide node; kNone for no child
  };
  static constexpr std::uint32_t kInner = 0, kNone = 0xFFFFFFFFu;
  // A wide node with no children (every count kNone, every box empty).
  static WideNode childless();
  // Folds binary node `node` (not a leaf) and its subtree into wide_; returns its index there.
  std::uint32_t widen(std::uint32_t node);

  static constexpr std::uint32_t kLeafTriangles = 4;
  static constexpr std::size_t kMaxDepth = 64;

  // The walk: from a best squared distance (and, if `seeded`, the point, triangle and feature that give it).
  bool search(const Eigen::Vector3d& query_m, double best_squared, bool seeded, Eigen::Vector3d best_point,
              std::uint32_t best_triangle, std::uint8_t best_feature, MeshPoint& out) const;
  // The answer for `query_m` at `point` on `triangle`'s `feature`, `squared` away.
  // The point of triangle t nearest `query_m`, and which feature it lies on (0 face, 1–3 edge, 4–6 vertex).
  Eigen::Vector3d closest_on(std::uint32_t t, const Eigen::Vector3d& query_m, std::uint8_t& feature) const;
  MeshPoint answer(const Eigen::Vector3d& query_m, const Eigen::Vector3d& point, double squared, std::uint32_t triangle,
                   std::uint8_t feature) const;
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, std::vector<Eigen::Vector3d>& centroids, int depth);
  void pseudo_normals();
  bool within_edges(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m) const;

  TriangleMesh mesh_;
  // In huge pages where large (huge_pages.h), as the mesh's own arrays.
  HugeVector<Node> nodes_;
  HugeVector<WideNode> wide_;  // wide_[0] is the root
  HugeVector<std::uint32_t> order_;                          // triangle indices, leaf by leaf
  HugeVector<Eigen::Vector3d> face_normals_;                 // unit
  HugeVector<std::array<Eigen::Vector3d, 3>> edge_normals_;  // per triangle, edges ab, bc, ca (unit)
  HugeVector<Eigen::Vector3d> vertex_normals_;               // unit, angle-weighted
  bool locally_convex_ = false;
};

// The point of triangle abc nearest p, and which feature it lies on (MeshPoint::feature's numbering).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, std::uint8_t& feature);

}  // namespace impetus
