// SPDX-License-Identifier: Apache-2.0
// A capsule: the points within `radius_m` of its axis segment, which runs along body z between the cap centres at
// ±length_m/2 (a capsule of zero length is a sphere).
#include "common/shape/shape_kind.h"

#include "common/runtime/json_node.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace impetus::shape_detail {
namespace {

void parse(const JsonNode& object, Shape& shape) {
  shape.radius_m = parse_length(object.required("radius_m"));
  shape.length_m = parse_length(object.required("length_m"), /*may_be_zero=*/true);
}

const char* problem(const Shape& shape) {
  return length_ok(shape.radius_m) && length_ok(shape.length_m, true) ? nullptr : "a capsule's size is out of range";
}

// A sphere about the axis point nearest the query.
SurfacePoint nearest(const Shape& shape, const Eigen::Vector3d& q) {
  const double half_length_m = 0.5 * shape.length_m;
  const Eigen::Vector3d axis_point_m(0.0, 0.0, std::clamp(q.z(), -half_length_m, half_length_m));
  return nearest_on_sphere(axis_point_m, shape.radius_m, q, Eigen::Vector3d::UnitX());
}

// The axis segment's support plus the radius.
double support(const Shape& shape, const Eigen::Vector3d& n) {
  return 0.5 * shape.length_m * std::abs(n.z()) + shape.radius_m;
}

Eigen::Vector3d bounds_half(const Shape& shape, const Eigen::Matrix3d& rotation) {
  return (0.5 * shape.length_m) * rotation.col(2).cwiseAbs() + Eigen::Vector3d::Constant(shape.radius_m);
}

// Along the segment the squared distance to the axis segment is a quadratic on each stretch where z is below, within
// or above [−half, half]: the least of their minima.
bool segment_enters(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) {
  const double inner_m = shape.radius_m - margin_m;
  if (!(inner_m > 0.0)) return false;  // shrunk past its axis: nothing left to enter
  const double half_m = 0.5 * shape.length_m;
  std::array<double, 4> cuts{0.0, 1.0, 1.0, 1.0};  // 0, the crossings of z = ±half inside (0, 1) in order, 1
  std::size_t stretches = 1;
  if (std::abs(d.z()) > 1e-300) {
    double first = (-half_m - a.z()) / d.z(), second = (half_m - a.z()) / d.z();
    if (first > second) std::swap(first, second);
    for (const double t : {first, second}) {
      if (t > 0.0 && t < 1.0) cuts[stretches++] = t;
    }
  }
  cuts[stretches] = 1.0;
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < stretches; ++k) {
    const double u = cuts[k], v = cuts[k + 1];
    const double z_mid = a.z() + 0.5 * (u + v) * d.z();
    if (std::abs(z_mid) <= half_m) {
      least = std::min(least, min_squared_norm(Eigen::Vector2d(a.head<2>()), Eigen::Vector2d(d.head<2>()), u, v));
    } else {
      const Eigen::Vector3d end_m(0.0, 0.0, z_mid > 0.0 ? half_m : -half_m);
      least = std::min(least, min_squared_norm(Eigen::Vector3d(a - end_m), d, u, v));
    }
  }
  return least < inner_m * inner_m;
}

double volume(const Shape& shape) {
  constexpr double kPi = std::numbers::pi;
  const double r = shape.radius_m;
  return kPi * r * r * shape.length_m + 4.0 / 3.0 * kPi * r * r * r;
}

// Per unit mass, the cylinder (mass fraction c) and the two hemispheres (fraction s) about the centre: about the axis
// c·r²/2 + s·2r²/5; across it c·(L²/12 + r²/4) + s·(2r²/5 + L²/4 + 3Lr/8) (each hemisphere's centre of mass lies 3r/8
// from its flat face, and 83/320·r² about it).
Eigen::Matrix3d inertia_per_kg(const Shape& shape) {
  const double r = shape.radius_m, l = shape.length_m;
  const double cylinder_m3 = r * r * l, spheres_m3 = 4.0 / 3.0 * r * r * r;  // both × π
  const double c = cylinder_m3 / (cylinder_m3 + spheres_m3), s = 1.0 - c;
  const double across = c * (l * l / 12.0 + r * r / 4.0) + s * (0.4 * r * r + l * l / 4.0 + 3.0 * l * r / 8.0);
  const double along = c * r * r / 2.0 + s * 0.4 * r * r;
  return Eigen::Vector3d(across, across, along).asDiagonal();
}

// Its planes are retaken with the radius; a finger inside may lie farther along the axis: the bounding cylinder's
// diagonal.
double plane_extent(const Shape& shape) { return shape.radius_m; }
double describes_within(const Shape& shape) {
  return std::hypot(2.0 * shape.radius_m, 2.0 * (0.5 * shape.length_m + shape.radius_m));
}

// The sphere of its radius about the axis point nearest `around_m`, so the finger follows the side and rounds the caps
// every tick, and leaves the capsule where the capsule ends. On the axis there is no direction: the plane stays.
void retake(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d axis = plane.axes.col(2);
  const double half_length_m = 0.5 * plane.shape.length_m;
  const double along_m = std::clamp(axis.dot(around_m - plane.com_m), -half_length_m, half_length_m);
  retake_about_centre(plane, plane.com_m + along_m * axis, plane.shape.radius_m, around_m);
}

// Its two cap centres at its radius (its side is its axis, an edge).
int contact_samples(const Shape& shape, ContactSamples& samples) {
  samples[0] = {Eigen::Vector3d(0.0, 0.0, -0.5 * shape.length_m), shape.radius_m};
  samples[1] = {Eigen::Vector3d(0.0, 0.0, 0.5 * shape.length_m), shape.radius_m};
  return 2;
}

// The axis, cap centre to cap centre, swept by the radius: the whole capsule.
int contact_edges(const Shape& shape, ContactEdges& edges) {
  edges[0] = {Eigen::Vector3d(0.0, 0.0, -0.5 * shape.length_m), Eigen::Vector3d(0.0, 0.0, 0.5 * shape.length_m),
              shape.radius_m};
  return 1;
}

constexpr std::string_view kKeys[] = {"radius_m", "length_m"};

}  // namespace

const ShapeKindOps kCapsuleOps{
    .name = "capsule",
    .traits = {.carries_axes = true, .flat_faces = false, .round = false, .normal_through_core = true, .convex = true},
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
    .describes_within = describes_within,
    .retake = retake,
    .nearest_faces = nullptr,
    .support_corners = nullptr,
    .contact_samples = contact_samples,
    .contact_edges = contact_edges,
};

}  // namespace impetus::shape_detail
