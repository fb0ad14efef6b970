// SPDX-License-Identifier: Apache-2.0
#pragma once
// The geometry behind a mesh shape (ShapeKind::mesh), found by the content hash its descriptor carries.
//
// A mesh's triangles are too many for the fixed-size descriptor that crosses the links, so the descriptor carries
// their hash and each process that needs the geometry loads the same file and registers it here (the world manager
// does when it loads a scene, and the haptic controller given the same scene: common/mesh/mesh_object.h). A process
// that has not loaded it (a viewer; a haptic controller without the scene) still has the descriptor's bounding box
// and radius, and uses the planes the world sends as they are.
//
// Frames and units: the body frame (its origin the mesh's centre of mass), SI. Registered geometry is immutable and
// lives until the process ends; lookups take no lock and allocate nothing, so any thread may query at any rate.

#include "common/shape/shape.h"

#include <Eigen/Core>

#include <cstdint>

namespace impetus {

// Where a way goes into a mesh through a triangle's outer side (MeshGeometry::first_entry).
struct MeshEntry {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the triangle (within the query's tolerance of its edges)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the triangle's own unit outward normal
  double t = 0.0;                                     // along the way, in [0, 1]
  std::uint32_t triangle = 0;
};

// What the shape module asks of a mesh. Every function is const, allocation-free and never throws.
class MeshGeometry {
 public:
  virtual ~MeshGeometry() = default;
  // Nearest surface point and its outward (pseudo-)normal; signed distance negative inside (closed meshes).
  virtual SurfacePoint nearest(const Eigen::Vector3d& query_m) const = 0;
  // max over the vertices of normal·x.
  virtual double support(const Eigen::Vector3d& normal) const = 0;
  // Whether `a` + t·`d`, t in [0, 1], passes through the mesh's inside deeper than `margin_m`: an end inside by more
  // than the margin, or a crossing of the surface past the first `margin_m` of the way (a way that starts on the
  // surface and leaves does not enter; one through a thin wall does).
  virtual bool segment_enters(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) const = 0;
  // The first triangle whose outer side the way from `a` to `b` goes in through, skipping the `skip_count`
  // triangles at `skip`: `a` in front of its plane or at most `tolerance_m` behind it, `b` more than `tolerance_m`
  // behind it, the crossing within `tolerance_m` of the triangle. False if the way goes in through none. What the
  // god-object's walk over the triangles asks (haptic_controller/mesh_walk.h).
  virtual bool first_entry(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance_m,
                           const std::uint32_t* skip, int skip_count, MeshEntry& out) const = 0;
  // Whether `x` lies on triangle `triangle` (an index first_entry gave): within `tolerance_m` of its plane and of its
  // edges. `out` is then the foot of `x` on its plane, with its normal. False for an unknown index.
  virtual bool on_triangle(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m,
                           MeshEntry& out) const = 0;
  // Half extents of the smallest world-aligned box centred on the origin that holds the mesh turned by `rotation`:
  // max over the vertices of |(rotation·x)_i| (shape.h's bounds are centred on the body's origin).
  virtual Eigen::Vector3d bounds_half(const Eigen::Matrix3d& rotation) const = 0;
  // Whether every edge has two triangles (a body with an inside; the pseudo-normals' side is exact). An open mesh's
  // side is that of its triangles' winding only near them.
  virtual bool closed() const = 0;
  // Whether the mesh bounds a convex body (closed, every edge bent outward or flat). Then the body lies behind every
  // triangle's plane: a point on or in front of any of them is outside it.
  virtual bool convex() const = 0;
  // Its contact features (common/shape/shape.h), where they stand for it: the corners and sharp edges of a convex
  // mesh of at most kMaxContactSamples corners and kMaxContactEdges sharp edges; 0 otherwise (a tool cannot be made
  // of it, and a tool meets it as its plane).
  virtual int contact_samples(ContactSamples& samples) const {
    (void)samples;
    return 0;
  }
  virtual int contact_edges(ContactEdges& edges) const {
    (void)edges;
    return 0;
  }
  virtual double volume_m3() const = 0;
  virtual Eigen::Matrix3d inertia_per_kg() const = 0;  // m², about the centre of mass, body frame
};

// Registers `geometry` under `hash` (no-op if a geometry of that hash is there: the same triangles). Throws
// std::length_error past kMaxMeshGeometries distinct meshes in one process. Not for the 1 kHz path.
void register_mesh_geometry(std::uint64_t hash, const MeshGeometry* geometry);
// The geometry registered under `hash`, or nullptr.
const MeshGeometry* find_mesh_geometry(std::uint64_t hash);

inline constexpr std::size_t kMaxMeshGeometries = 256;

}  // namespace impetus
