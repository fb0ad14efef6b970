// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a kind of shape provides to the dispatch table (shape.cpp): one constant of this type per kind, defined in the
// kind's own file. Only the shape module includes this header; everyone else calls shape.h.

#include "common/shape/shape.h"

#include <algorithm>
#include <array>
#include <span>
#include <string_view>

namespace impetus::shape_detail {

// A plane retaken under a proxy `around_m`, and a shape's geometry, as the kind defines them (shape.h says what each
// promises). A null function means the kind has no such thing (nearest_faces, support_corners for a curved shape).
struct ShapeKindOps {
  const char* name;
  ShapeTraits traits;
  std::span<const std::string_view> keys;
  void (*parse)(const JsonNode& object, Shape& shape);
  const char* (*problem)(const Shape& shape);  // dimensions only; finiteness is checked by the caller
  SurfacePoint (*nearest)(const Shape& shape, const Eigen::Vector3d& query_m);
  double (*support)(const Shape& shape, const Eigen::Vector3d& normal_body);
  // Half extents of the world-aligned bounding box for a body whose rotation (body → world) is `rotation`.
  Eigen::Vector3d (*bounds_half)(const Shape& shape, const Eigen::Matrix3d& rotation);
  // `a` + t·`d`, t in [0, 1], body frame.
  bool (*segment_enters)(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m);
  double (*volume)(const Shape& shape);
  Eigen::Matrix3d (*inertia_per_kg)(const Shape& shape);  // m²: inertia of a unit mass, body frame
  double (*plane_extent)(const Shape& shape);
  double (*describes_within)(const Shape& shape);
  void (*retake)(ShapePlane& plane, const Eigen::Vector3d& around_m);
  int (*nearest_faces)(const Shape& shape, const Eigen::Vector3d& q, double tolerance_m,
                       std::array<Eigen::Vector3d, 3>& normals);
  int (*support_corners)(const Shape& shape, const Eigen::Matrix3d& axes, const Eigen::Vector3d& n,
                         std::array<Eigen::Vector3d, 4>& corners);
  int (*contact_samples)(const Shape& shape, ContactSamples& samples);
  int (*contact_edges)(const Shape& shape, ContactEdges& edges);
};

extern const ShapeKindOps kBoxOps;
extern const ShapeKindOps kSphereOps;
extern const ShapeKindOps kCapsuleOps;
extern const ShapeKindOps kCylinderOps;
extern const ShapeKindOps kMeshOps;

// Shared by the kind files.

// Below this distance from a centre (or axis) the direction to a query point is numerically meaningless (1 nm, far
// under any modelled feature), so a fixed fallback direction is used instead.
inline constexpr double kDegenerateDistance_m = 1e-9;
// A plane within 1° of a face's normal is that face's, as the interpolation or the local model turned it (the local
// model's blend toward a new frame turns a face by a fraction of what the body turned in one period); an edge's or a
// corner's plane from the world is tilted by more unless the proxy was within 1/57 of its distance of the face plane.
inline constexpr double kSameFaceCosine = 0.99984769515;  // cos 1°

// Sphere of `radius_m` about `centre_m`: the radial direction, also from inside.
SurfacePoint nearest_on_sphere(const Eigen::Vector3d& centre_m, double radius_m, const Eigen::Vector3d& query_m,
                               const Eigen::Vector3d& fallback_normal);
// The tangent plane of the sphere of `radius_m` about `centre_m` at its point nearest `around_m`; left as it is when
// `around_m` is at the centre.
void retake_about_centre(ShapePlane& plane, const Eigen::Vector3d& centre_m, double radius_m,
                         const Eigen::Vector3d& around_m);
// The parameter interval [t0, t1] that the segment `from` + t·`delta` spends within |coordinate| < half; false if none
// (and for half ≤ 0).
bool clip_slab(double from, double delta, double half, double& t0, double& t1);
// Squared distance from the origin to the segment a + t·d, t in [t0, t1] (2-D or 3-D).
template <typename Vector>
double min_squared_norm(const Vector& a, const Vector& d, double t0, double t1) {
  const double dd = d.squaredNorm();
  const double t = dd > 0.0 ? std::clamp(-a.dot(d) / dd, t0, t1) : t0;
  return (a + t * d).squaredNorm();
}
// A dimension read from a scene, within the length limits (common/contract/limits.h), or [0, max] for `may_be_zero`.
double parse_length(const JsonNode& value, bool may_be_zero = false);
// A dimension that links accept: finite and within the scene's limits.
bool length_ok(double length_m, bool may_be_zero = false);

}  // namespace impetus::shape_detail
