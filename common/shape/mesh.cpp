// SPDX-License-Identifier: Apache-2.0
// A triangle mesh a user brings (docs/meshes.md): its triangles, in the body frame about their centre of mass, are
// in the process's mesh registry under the hash the descriptor carries (mesh_geometry.h). The world manager, which
// loads the scene, has them; the haptic side renders the planes the world sends as they are (the paper's §3.1), so
// a mesh's plane is not retaken from the shape. Without its geometry (a process that did not load the file) a mesh
// answers as the ball of its radius_m, which holds it. A mesh may be concave (traits().convex is false): the world
// takes its plane at the nearest point every step and keeps no face.
#include "common/shape/shape_kind.h"

#include "common/shape/mesh_geometry.h"

#include <cmath>
#include <numbers>

namespace impetus::shape_detail {
namespace {

const char* problem(const Shape& shape) {
  if (shape.mesh_hash == 0) return "a mesh names no triangles (hash 0)";
  if (!length_ok(shape.radius_m)) return "a mesh's radius is out of range";
  for (int i = 0; i < 3; ++i) {
    if (!length_ok(shape.box_size_m[i], true)) return "a mesh's bounding box is out of range";
  }
  return nullptr;
}

SurfacePoint nearest(const Shape& shape, const Eigen::Vector3d& q) {
  if (const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash)) return mesh->nearest(q);
  return nearest_on_sphere(Eigen::Vector3d::Zero(), shape.radius_m, q, Eigen::Vector3d::UnitZ());
}

double support(const Shape& shape, const Eigen::Vector3d& n) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->support(n) : shape.radius_m;
}

Eigen::Vector3d bounds_half(const Shape& shape, const Eigen::Matrix3d& rotation) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->bounds_half(rotation) : Eigen::Vector3d::Constant(shape.radius_m);
}

double volume(const Shape& shape) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->volume_m3() : 0.0;
}

Eigen::Matrix3d inertia_per_kg(const Shape& shape) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->inertia_per_kg() : Eigen::Matrix3d::Zero();
}

// No two points of the mesh are farther apart than the diameter of the ball about its centre of mass that holds it.
double plane_extent(const Shape& shape) { return 2.0 * shape.radius_m; }

// Read from a scene by the world manager, which loads the file (world_manager/mesh_objects.h).
constexpr std::string_view kKeys[] = {"file", "scale"};

}  // namespace

const ShapeKindOps kMeshOps{
    .name = "mesh",
    .traits = {.carries_axes = false, .flat_faces = false, .round = false, .normal_through_core = false,
               .convex = false, .planes_as_sent = true},
    .keys = kKeys,
    .parse = nullptr,
    .problem = problem,
    .nearest = nearest,
    .support = support,
    .bounds_half = bounds_half,
    .segment_enters = nullptr,  // asked only of convex shapes' kept faces (traits().convex)
    .volume = volume,
    .inertia_per_kg = inertia_per_kg,
    .plane_extent = plane_extent,
    .describes_within = plane_extent,
    .retake = nullptr,
    .nearest_faces = nullptr,
    .support_corners = nullptr,
};

}  // namespace impetus::shape_detail
