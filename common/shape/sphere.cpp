// SPDX-License-Identifier: Apache-2.0
// A sphere: `radius_m` about the centre of mass. Its plane carries the centre as point − radius·normal (the axes are
// not sent), so a plane moved by the interpolation or the local model keeps its sphere.
#include "common/shape/shape_kind.h"

#include "common/runtime/json_node.h"

#include <cmath>
#include <numbers>

namespace impetus::shape_detail {
namespace {

void parse(const JsonNode& object, Shape& shape) { shape.radius_m = parse_length(object.required("radius_m")); }

const char* problem(const Shape& shape) {
  return length_ok(shape.radius_m) ? nullptr : "a sphere's radius is out of range";
}

SurfacePoint nearest(const Shape& shape, const Eigen::Vector3d& q) {
  return nearest_on_sphere(Eigen::Vector3d::Zero(), shape.radius_m, q, Eigen::Vector3d::UnitZ());
}

double support(const Shape& shape, const Eigen::Vector3d&) { return shape.radius_m; }

Eigen::Vector3d bounds_half(const Shape& shape, const Eigen::Matrix3d&) {
  return Eigen::Vector3d::Constant(shape.radius_m);
}

bool segment_enters(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) {
  const double inner_m = shape.radius_m - margin_m;
  if (!(inner_m > 0.0)) return false;  // shrunk past its axis: nothing left to enter
  return min_squared_norm(a, d, 0.0, 1.0) < inner_m * inner_m;
}

double volume(const Shape& shape) {
  const double r = shape.radius_m;
  return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

Eigen::Matrix3d inertia_per_kg(const Shape& shape) {  // solid ball: 2/5 r²
  return Eigen::Matrix3d::Identity() * (0.4 * shape.radius_m * shape.radius_m);
}

double plane_extent(const Shape& shape) { return shape.radius_m; }

// The tangent plane at the sphere's point nearest `around_m`, as Zilles & Salisbury's god-object follows a curved
// surface: the proxy walks over the ball instead of along a plane, and a push along the normal passes the centre.
void retake(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  retake_about_centre(plane, plane.point_m - plane.shape.radius_m * plane.normal, plane.shape.radius_m, around_m);
}

// A ball is its centre at its radius: exact against any other body.
int contact_samples(const Shape& shape, ContactSamples& samples) {
  samples[0] = {Eigen::Vector3d::Zero(), shape.radius_m};
  return 1;
}

constexpr std::string_view kKeys[] = {"radius_m"};

}  // namespace

const ShapeKindOps kSphereOps{
    .name = "sphere",
    .traits = {.carries_axes = false, .flat_faces = false, .round = true, .normal_through_core = true, .convex = true},
    .keys = kKeys,
    .parse = parse,
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
    .contact_edges = nullptr,
};

}  // namespace impetus::shape_detail
