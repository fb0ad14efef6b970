// SPDX-License-Identifier: Apache-2.0
// The one place that dispatches on a shape's kind: a table of each kind's functions (shape_kind.h), indexed by
// ShapeKind. Everything else asks this file.
#include "common/shape/shape.h"

#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"
#include "common/shape/shape_kind.h"

#include <cmath>

namespace impetus {
namespace {

using shape_detail::ShapeKindOps;

// No shape: no geometry, every function answers "nothing" (shape.h).
const ShapeKindOps kNoneOps{
    .name = "none",
    .traits = {},
    .keys = {},
    .parse = nullptr,
    .problem = nullptr,
    .nearest = nullptr,
    .support = nullptr,
    .bounds_half = nullptr,
    .segment_enters = nullptr,
    .volume = nullptr,
    .inertia_per_kg = nullptr,
    .plane_extent = nullptr,
    .describes_within = nullptr,
    .retake = nullptr,
    .nearest_faces = nullptr,
    .support_corners = nullptr,
    .contact_samples = nullptr,
    .contact_edges = nullptr,
};

// Indexed by ShapeKind's value.
const ShapeKindOps* const kKinds[kShapeKindCount] = {
    &kNoneOps,
    &shape_detail::kBoxOps,
    &shape_detail::kSphereOps,
    &shape_detail::kCapsuleOps,
    &shape_detail::kCylinderOps,
    &shape_detail::kMeshOps,
};

const ShapeKindOps& ops(ShapeKind kind) {
  const auto index = static_cast<std::uint32_t>(kind);
  return index < kShapeKindCount ? *kKinds[index] : kNoneOps;
}

bool all_finite(const Shape& shape) {
  return std::isfinite(shape.box_size_m[0]) && std::isfinite(shape.box_size_m[1]) &&
         std::isfinite(shape.box_size_m[2]) && std::isfinite(shape.radius_m) && std::isfinite(shape.length_m);
}

}  // namespace

const char* to_string(ShapeKind kind) { return ops(kind).name; }

bool shape_kind_from_string(std::string_view name, ShapeKind& kind) {
  for (std::uint32_t k = 1; k < kShapeKindCount; ++k) {
    if (name == kKinds[k]->name) {
      kind = static_cast<ShapeKind>(k);
      return true;
    }
  }
  return false;
}

std::string shape_kind_names() {
  std::vector<std::string> names;
  for (std::uint32_t k = 1; k < kShapeKindCount; ++k) names.emplace_back(kKinds[k]->name);
  return one_of(names);
}

const ShapeTraits& traits(ShapeKind kind) { return ops(kind).traits; }

std::span<const std::string_view> shape_keys(ShapeKind kind) { return ops(kind).keys; }

ShapeKind parse_shape_kind(const JsonNode& node) {
  ShapeKind kind = ShapeKind::none;
  if (!shape_kind_from_string(node.string(), kind)) node.fail("unknown shape, expected " + shape_kind_names());
  return kind;
}

Shape parse_shape(const JsonNode& object, ShapeKind kind) {
  Shape shape;
  shape.kind = kind;
  if (ops(kind).parse != nullptr) ops(kind).parse(object, shape);
  return shape;
}

const char* shape_problem(const Shape& shape) {
  if (static_cast<std::uint32_t>(shape.kind) >= kShapeKindCount) return "unknown shape kind";
  if (!all_finite(shape)) return "a shape's size is not finite";
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.problem != nullptr ? kind.problem(shape) : nullptr;
}

SurfacePoint nearest_surface_point_body(const Shape& shape, const Eigen::Vector3d& query_m) {
  const ShapeKindOps& kind = ops(shape.kind);
  if (kind.nearest == nullptr) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0};
  return kind.nearest(shape, query_m);
}

double support_m(const Shape& shape, const Eigen::Vector3d& normal_body) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.support != nullptr ? kind.support(shape, normal_body) : 0.0;
}

bool segment_enters_body(const Shape& shape, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                         double margin_m) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.segment_enters != nullptr && kind.segment_enters(shape, from_m, Eigen::Vector3d(to_m - from_m), margin_m);
}

int nearest_faces_body(const Shape& shape, const Eigen::Vector3d& q, double tolerance_m,
                       std::array<Eigen::Vector3d, 3>& normals) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.nearest_faces != nullptr ? kind.nearest_faces(shape, q, tolerance_m, normals) : 0;
}

double volume_m3(const Shape& shape) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.volume != nullptr ? kind.volume(shape) : 0.0;
}

Eigen::Matrix3d inertia_kgm2(const Shape& shape, double mass_kg) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.inertia_per_kg != nullptr ? Eigen::Matrix3d(mass_kg * kind.inertia_per_kg(shape))
                                        : Eigen::Matrix3d::Zero();
}

double plane_extent_m(const Shape& shape) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.plane_extent != nullptr ? kind.plane_extent(shape) : 0.0;
}

double describes_within_m(const Shape& shape) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.describes_within != nullptr ? kind.describes_within(shape) : 0.0;
}

SurfacePoint nearest_surface_point(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m) {
  const Eigen::Vector3d query_body_m = pose.orientation.conjugate() * (query_m - pose.position_m);
  const SurfacePoint body = nearest_surface_point_body(shape, query_body_m);
  return {pose.orientation * body.point_m + pose.position_m, pose.orientation * body.normal, body.signed_distance_m};
}

SurfacePoint supporting_plane(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m,
                              const Eigen::Vector3d& normal_body) {
  const Eigen::Vector3d& n = normal_body;
  const double h_m = support_m(shape, n);  // about the body origin
  const Eigen::Vector3d query_body_m = pose.orientation.conjugate() * (query_m - pose.position_m);
  const double signed_distance_m = n.dot(query_body_m) - h_m;
  // The query projected onto the plane; for a round shape its support point r·n instead, since its plane carries the
  // centre as point − r·normal.
  const Eigen::Vector3d point_body_m = traits(shape.kind).round ? Eigen::Vector3d(h_m * n)
                                                                : Eigen::Vector3d(query_body_m - signed_distance_m * n);
  return {pose.orientation * point_body_m + pose.position_m, pose.orientation * n, signed_distance_m};
}

Eigen::AlignedBox3d world_bounds(const Shape& shape, const BodyPose& pose) {
  const ShapeKindOps& kind = ops(shape.kind);
  const Eigen::Vector3d half_m = kind.bounds_half != nullptr
                                     ? kind.bounds_half(shape, pose.orientation.toRotationMatrix())
                                     : Eigen::Vector3d::Zero();
  return {pose.position_m - half_m, pose.position_m + half_m};
}

double largest_extent_m(const Shape& shape) { return world_bounds(shape, BodyPose{}).sizes().maxCoeff(); }

void retake_plane(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  const ShapeKindOps& kind = ops(plane.shape.kind);
  if (kind.retake != nullptr) kind.retake(plane, around_m);
}

bool segment_enters(const ShapePlane& plane, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                    double margin_m) {
  const ShapeKindOps& kind = ops(plane.shape.kind);
  if (kind.segment_enters == nullptr) return false;
  if (kind.traits.round) {  // the centre is point − radius·normal; any axes serve
    const Eigen::Vector3d centre_m = plane.point_m - plane.shape.radius_m * plane.normal;
    return kind.segment_enters(plane.shape, Eigen::Vector3d(from_m - centre_m), Eigen::Vector3d(to_m - from_m),
                               margin_m);
  }
  const Eigen::Vector3d a = plane.axes.transpose() * (from_m - plane.com_m);  // body frame
  const Eigen::Vector3d d = plane.axes.transpose() * (to_m - from_m);
  return kind.segment_enters(plane.shape, a, d, margin_m);
}

int support_corners(const Shape& shape, const Eigen::Matrix3d& axes, const Eigen::Vector3d& n,
                    std::array<Eigen::Vector3d, 4>& corners) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.support_corners != nullptr ? kind.support_corners(shape, axes, n, corners) : 0;
}

int contact_edges(const Shape& shape, ContactEdges& edges) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.contact_edges != nullptr ? kind.contact_edges(shape, edges) : 0;
}

int contact_samples(const Shape& shape, ContactSamples& samples) {
  const ShapeKindOps& kind = ops(shape.kind);
  return kind.contact_samples != nullptr ? kind.contact_samples(shape, samples) : 0;
}

}  // namespace impetus
