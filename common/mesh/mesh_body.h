// SPDX-License-Identifier: Apache-2.0
#pragma once
// A user's mesh as the shape of a scene body (docs/meshes.md): read, checked, moved so that its origin is the body's
// centre of mass, with its BVH, and registered in the shape module under its hash (common/shape/mesh_geometry.h).
//
// The body frame: a closed mesh's origin is its centre of mass (uniform density), its axes the file's. An open mesh
// (a static terrain or shell: no volume, so no centre of mass) is centred on its bounding box instead. Units SI.
// A MeshBody is immutable and lives until the process ends (the registry hands out plain pointers to it).

#include "common/mesh/mesh_bvh.h"
#include "common/mesh/smooth_surface.h"
#include "common/shape/mesh_geometry.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace impetus {

class MeshBody final : public MeshGeometry {
 public:
  // Reads `path` scaled by `scale` and checks it (mesh_check.h require_usable: a `dynamic` body's mesh must be
  // closed; one wound inside out is turned around). Throws InputError naming the file and what is wrong. The same file
  // at the same scale is read once per process. Not for the 1 kHz path.
  static const MeshBody& load(const std::string& path, const Eigen::Vector3d& scale, bool dynamic);

  // The descriptor a scene object and every plane of it carry.
  const Shape& shape() const { return shape_; }
  // Where the body's origin lies in the (scaled) file's frame: a scene's position_m puts this point there.
  const Eigen::Vector3d& origin_in_file_m() const { return origin_in_file_m_; }
  bool closed() const override { return closed_; }
  bool convex() const override { return closed_ && bvh_.locally_convex(); }
  bool winding_flipped() const { return flipped_; }
  const MeshBvh& bvh() const { return bvh_; }
  // The smooth surface the triangles stand for (smooth_surface.h), built on the first call (any thread; O(n)).
  const SmoothSurface& smooth_surface() const;

  SurfacePoint nearest(const Eigen::Vector3d& query_m) const override;
  double support(const Eigen::Vector3d& normal) const override;
  bool segment_enters(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) const override;
  bool first_entry(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance_m, const std::uint32_t* skip,
                   int skip_count, MeshEntry& out) const override {
    return bvh_.first_entry(a, b, tolerance_m, skip, skip_count, out);
  }
  bool on_triangle(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m,
                   MeshEntry& out) const override {
    return bvh_.on_triangle(triangle, x, tolerance_m, out);
  }
  Eigen::Vector3d bounds_half(const Eigen::Matrix3d& rotation) const override;
  int contact_samples(ContactSamples& samples) const override;
  int contact_edges(ContactEdges& edges) const override;
  double volume_m3() const override { return volume_m3_; }
  Eigen::Matrix3d inertia_per_kg() const override { return inertia_per_kg_; }

 private:
  MeshBody(TriangleMesh mesh, bool closed, bool flipped);
  void take_contact_features();

  Shape shape_;
  Eigen::Vector3d origin_in_file_m_ = Eigen::Vector3d::Zero();
  bool closed_ = false;
  bool flipped_ = false;
  double volume_m3_ = 0.0;
  Eigen::Matrix3d inertia_per_kg_ = Eigen::Matrix3d::Zero();
  MeshBvh bvh_;
  ContactSamples samples_{};  // its corners and sharp edges, if they stand for it (contact_samples)
  int sample_count_ = 0;
  ContactEdges edges_{};
  int edge_count_ = 0;
  mutable std::once_flag smooth_built_;
  mutable std::unique_ptr<SmoothSurface> smooth_;
};

}  // namespace impetus
