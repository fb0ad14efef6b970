// SPDX-License-Identifier: Apache-2.0
#pragma once
// A user's triangle mesh (docs/meshes.md): vertices and triangles, in the mesh's own frame, metres. Built by
// load_mesh (mesh_file.h) and checked by check_mesh (mesh_check.h); what a body made of it weighs and how it turns
// comes from mass_properties (mass_properties.h); nearest points from MeshBvh (mesh_bvh.h).
//
// Winding: counter-clockwise seen from outside, so (b − a) × (c − a) points out of a closed mesh.

#include "common/mesh/huge_pages.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace impetus {

// Held in huge pages where large (huge_pages.h): the servo's walk reads the triangles it meets at random.
struct TriangleMesh {
  HugeVector<Eigen::Vector3d> vertices_m;
  HugeVector<std::array<std::uint32_t, 3>> triangles;
};

// Limits a mesh file must keep, each with its reason.
struct MeshLimits {
  // 2·10^6 triangles: a scanned object at fine resolution. The BVH and the checks hold about 235 bytes a triangle
  // (docs/meshes.md), 470 MB at the limit, the most a desktop trial should ask of memory.
  static constexpr std::size_t kMaxTriangles = 2'000'000;
  // A coordinate beyond 1 km is not a desk-sized object in metres: most likely millimetres read as metres, or garbage.
  static constexpr double kMaxCoordinate_m = 1000.0;
};

// FNV-1a over the vertices' and triangles' bytes, in order: both processes load the same file and agree on it by this
// hash (as the SPIDAR geometry's, common/spidar/geometry.h).
std::uint64_t mesh_hash(const TriangleMesh& mesh);

// Each triangle's unit normal, (b − a) × (c − a) normalised (+z for a degenerate one, which check_mesh refuses).
std::vector<Eigen::Vector3d> face_normals(const TriangleMesh& mesh);
// Each vertex's angle-weighted normal (Thürmer and Wüthrich 1998): the sum of its triangles' normals, each times the
// triangle's angle at the vertex, normalised. It does not depend on how the faces around it are cut into triangles.
std::vector<Eigen::Vector3d> angle_weighted_normals(const TriangleMesh& mesh,
                                                    const std::vector<Eigen::Vector3d>& face_normals);

}  // namespace impetus
