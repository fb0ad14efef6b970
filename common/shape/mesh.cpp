// SPDX-License-Identifier: Apache-2.0
// A triangle mesh a user brings (docs/meshes.md): its triangles, in the body frame about their centre of mass, are
// in the process's mesh registry under the hash the descriptor carries (mesh_geometry.h). The world manager loads
// them with the scene, the haptic controller with --meshes-from the same scene. Without them (a process that did not
// load the file) a mesh answers as the ball of its radius_m, which holds it, and its plane is left as sent. A mesh
// may be concave (traits().convex is false): the world takes its plane at the nearest point every step and keeps no
// face.
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

bool segment_enters(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr && mesh->segment_enters(a, d, margin_m);
}

int contact_samples(const Shape& shape, ContactSamples& samples) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->contact_samples(samples) : 0;
}

int contact_edges(const Shape& shape, ContactEdges& edges) {
  const MeshGeometry* mesh = find_mesh_geometry(shape.mesh_hash);
  return mesh != nullptr ? mesh->contact_edges(edges) : 0;
}

// The tangent plane at the mesh's point nearest `around_m` (the proxy), with the pseudo-normal of the face, edge or
// vertex it lies on, as a sphere's is retaken: the proxy follows the surface tick by tick between world frames.
void retake(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  const MeshGeometry* mesh = find_mesh_geometry(plane.shape.mesh_hash);
  if (mesh == nullptr) return;  // the triangles are not here: the plane as sent
  const SurfacePoint nearest = mesh->nearest(plane.axes.transpose() * (around_m - plane.com_m));
  plane.point_m = plane.com_m + plane.axes * nearest.point_m;
  plane.normal = plane.axes * nearest.normal;
}

// No two points of the mesh are farther apart than the diameter of the ball about its centre of mass that holds it.
double plane_extent(const Shape& shape) { return 2.0 * shape.radius_m; }

// Read from a scene by the world manager and the haptic controller, which load the file (common/mesh/mesh_object.h);
// "surface" by the world manager alone (world_manager/scene.cpp).
constexpr std::string_view kKeys[] = {"file", "scale", "surface"};

}  // namespace

const ShapeKindOps kMeshOps{
    .name = "mesh",
    .traits = {.carries_axes = true, .flat_faces = false, .round = false, .normal_through_core = false,
               .convex = false},
    .keys = kKeys,
    .parse = nullptr,
    .problem = problem,
    .nearest = nearest,
    .support = support,
    .bounds_half = bounds_half,
    .segment_enters = segment_enters,
    .volume = volume,
    .inertia_per_kg = inertia_per_kg,
    .plane_extent = plane_extent,
    .describes_within = plane_extent,
    .retake = retake,
    .nearest_faces = nullptr,
    .support_corners = nullptr,
    .contact_samples = contact_samples,
    .contact_edges = contact_edges,
};

}  // namespace impetus::shape_detail
