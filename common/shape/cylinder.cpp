// SPDX-License-Identifier: Apache-2.0
// A cylinder: `radius_m` about body z, flat caps at ±length_m/2.
#include "common/shape/shape_kind.h"

#include "common/runtime/json_node.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace impetus::shape_detail {
namespace {

void parse(const JsonNode& object, Shape& shape) {
  shape.radius_m = parse_length(object.required("radius_m"));
  shape.length_m = parse_length(object.required("length_m"));
}

const char* problem(const Shape& shape) {
  return length_ok(shape.radius_m) && length_ok(shape.length_m) ? nullptr : "a cylinder's size is out of range";
}

SurfacePoint nearest(const Shape& shape, const Eigen::Vector3d& q) {
  const double radius_m = shape.radius_m, half_length_m = 0.5 * shape.length_m;
  const double radial_m = std::hypot(q.x(), q.y());
  const Eigen::Vector2d radial_dir =
      radial_m > kDegenerateDistance_m ? Eigen::Vector2d(q.x() / radial_m, q.y() / radial_m) : Eigen::Vector2d(1, 0);
  const bool outside = radial_m > radius_m || std::abs(q.z()) > half_length_m;
  if (outside) {
    const double clamped_radial_m = std::min(radial_m, radius_m);
    const Eigen::Vector3d clamped(radial_dir.x() * clamped_radial_m, radial_dir.y() * clamped_radial_m,
                                  std::clamp(q.z(), -half_length_m, half_length_m));
    const Eigen::Vector3d offset_m = q - clamped;
    const double distance_m = offset_m.norm();
    return {clamped, offset_m / distance_m, distance_m};
  }
  const double side_gap_m = radius_m - radial_m;
  const double cap_gap_m = half_length_m - std::abs(q.z());
  if (cap_gap_m < side_gap_m) {
    const double side = q.z() >= 0.0 ? 1.0 : -1.0;
    return {Eigen::Vector3d(q.x(), q.y(), side * half_length_m), Eigen::Vector3d(0, 0, side), -cap_gap_m};
  }
  const Eigen::Vector3d normal(radial_dir.x(), radial_dir.y(), 0.0);
  return {Eigen::Vector3d(radial_dir.x() * radius_m, radial_dir.y() * radius_m, q.z()), normal, -side_gap_m};
}

// A cap's rim: the disc's support plus the half length along the axis.
double support(const Shape& shape, const Eigen::Vector3d& n) {
  return 0.5 * shape.length_m * std::abs(n.z()) + shape.radius_m * std::hypot(n.x(), n.y());
}

// A disc of radius r with unit normal u extends r·sqrt(1 − u_i²) along world axis i.
Eigen::Vector3d bounds_half(const Shape& shape, const Eigen::Matrix3d& rotation) {
  const Eigen::Vector3d axis = rotation.col(2);
  Eigen::Vector3d half_m;
  for (int i = 0; i < 3; ++i) {
    half_m[i] = 0.5 * shape.length_m * std::abs(axis[i]) +
                shape.radius_m * std::sqrt(std::max(0.0, 1.0 - axis[i] * axis[i]));
  }
  return half_m;
}

bool segment_enters(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) {
  const double inner_m = shape.radius_m - margin_m;
  if (!(inner_m > 0.0)) return false;  // shrunk past its axis: nothing left to enter
  double t0 = 0.0, t1 = 1.0;
  if (!clip_slab(a.z(), d.z(), 0.5 * shape.length_m - margin_m, t0, t1)) return false;
  return min_squared_norm(Eigen::Vector2d(a.head<2>()), Eigen::Vector2d(d.head<2>()), t0, t1) < inner_m * inner_m;
}

double volume(const Shape& shape) { return std::numbers::pi * shape.radius_m * shape.radius_m * shape.length_m; }

// Solid cylinder of unit mass: r²/2 about its axis, (3r² + L²)/12 across it.
Eigen::Matrix3d inertia_per_kg(const Shape& shape) {
  const double r2 = shape.radius_m * shape.radius_m, l2 = shape.length_m * shape.length_m;
  const double across = (3.0 * r2 + l2) / 12.0;
  return Eigen::Vector3d(across, across, 0.5 * r2).asDiagonal();
}

double plane_extent(const Shape& shape) { return shape.radius_m; }
double describes_within(const Shape& shape) { return std::hypot(2.0 * shape.radius_m, 2.0 * (0.5 * shape.length_m)); }

// Flat caps and a curved side. The plane is the side's (normal square to the axis) or a cap's (the normal nearer the
// axis). Beside the side a side plane is the tangent plane under `around_m`; over its cap a cap plane stays as the
// interpolation or the local model made it, as a box face's does; past the plane's own part (round a rim, or onto the
// other part) the cylinder's nearest point, its normal from there to `around_m`. A proxy on the surface gets the plane
// of the part it is on: its own cap's plane as it came, the side's tangent plane there, a cap's plane on a cap. Inside
// it gets the part the world chose (the one the plane faces), on the true surface.
//
// On the surface the plane must be the part's own even when it came tilted: a plane blended between a rim's and the
// side's (the proxy went round the rim between two frames) kept under a proxy on the side would carry the proxy off
// the surface onto the tilt, the next tick would bring it back to the side's tangent plane, and so on, a tick-by-tick
// hop of millimetres.
void retake(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d local_m = plane.axes.transpose() * (around_m - plane.com_m);  // body frame, axis z
  const double radius_m = plane.shape.radius_m;
  const double half_length_m = 0.5 * plane.shape.length_m;
  const Eigen::Vector3d normal_local = plane.axes.transpose() * plane.normal;
  const bool cap_plane = std::abs(normal_local.z()) > std::hypot(normal_local.x(), normal_local.y());
  const double radial_m = std::hypot(local_m.x(), local_m.y());
  const bool beside = radial_m > radius_m + kOnSurface_m;
  const bool beyond_cap = std::abs(local_m.z()) > half_length_m + kOnSurface_m;
  // Over its own cap a cap's plane stays; a rim's plane from the world (tilted off the axis) becomes the cap's there,
  // as a box edge's plane becomes its face's.
  const bool cap_as_moved = cap_plane && std::abs(normal_local.z()) >= kSameFaceCosine;
  if (!beside && !beyond_cap) {
    const bool on_side = radial_m >= radius_m - kOnSurface_m && radial_m > 0.0;
    const bool on_cap = std::abs(local_m.z()) >= half_length_m - kOnSurface_m;
    if (!on_side && !on_cap) {
      // Inside (the body moved onto the proxy): the part the world chose, but its own plane there, not a blend that
      // cuts into the body (between a rim's plane and a part's it passes inside the rim).
      if (cap_plane) {
        if (cap_as_moved) return;
        const double side = normal_local.z() > 0.0 ? 1.0 : -1.0;
        plane.normal = side * plane.axes.col(2);
        plane.point_m = plane.com_m + plane.axes * Eigen::Vector3d(local_m.x(), local_m.y(), side * half_length_m);
        return;
      }
      // The side at the azimuth the plane faces: exact even for a plane blended between two frames' tangent planes,
      // which lies on their chord, inside the side (r·(1 − cos(Δθ/2)): 0.5 mm for 36° on a 1 cm radius).
      const double out_m = std::hypot(normal_local.x(), normal_local.y());
      if (!(out_m > 0.0)) return;
      const Eigen::Vector3d out_local(normal_local.x() / out_m, normal_local.y() / out_m, 0.0);
      plane.normal = plane.axes * out_local;
      plane.point_m =
          plane.com_m + plane.axes * Eigen::Vector3d(radius_m * out_local.x(), radius_m * out_local.y(), local_m.z());
      return;
    }
    const double cap_side = local_m.z() >= 0.0 ? 1.0 : -1.0;
    if (on_cap && (!on_side || cap_plane)) {
      if (cap_as_moved && cap_side * normal_local.z() > 0.0) return;
      plane.normal = cap_side * plane.axes.col(2);
      plane.point_m = plane.com_m + plane.axes * Eigen::Vector3d(local_m.x(), local_m.y(), cap_side * half_length_m);
      return;
    }
    const Eigen::Vector3d out_local(local_m.x() / radial_m, local_m.y() / radial_m, 0.0);
    plane.normal = plane.axes * out_local;
    plane.point_m =
        plane.com_m + plane.axes * Eigen::Vector3d(radius_m * out_local.x(), radius_m * out_local.y(), local_m.z());
    return;
  }
  if (cap_as_moved && !beside && local_m.z() * normal_local.z() > 0.0) return;
  Eigen::Vector3d nearest_local_m(local_m.x(), local_m.y(), std::clamp(local_m.z(), -half_length_m, half_length_m));
  if (beside) nearest_local_m.head<2>() *= radius_m / radial_m;
  const Eigen::Vector3d offset_local_m = local_m - nearest_local_m;
  const double distance_m = offset_local_m.norm();
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) return;
  plane.normal = plane.axes * (offset_local_m / distance_m);
  plane.point_m = plane.com_m + plane.axes * nearest_local_m;
}

// Its rims as 16-gons: the points (against a plane a cylinder's deepest points are on a rim), and the chords between
// them (an edge of another body crossing a rim).
constexpr int kPerRim = 16;

Eigen::Vector3d rim_point(const Shape& shape, int k, double z_m) {
  const double angle = 2.0 * std::numbers::pi * k / kPerRim;
  return {shape.radius_m * std::cos(angle), shape.radius_m * std::sin(angle), z_m};
}

int contact_samples(const Shape& shape, ContactSamples& samples) {
  static_assert(2 * kPerRim <= kMaxContactSamples);
  int count = 0;
  for (const double z_m : {-0.5 * shape.length_m, 0.5 * shape.length_m}) {
    for (int k = 0; k < kPerRim; ++k) samples[static_cast<std::size_t>(count++)] = {rim_point(shape, k, z_m), 0.0};
  }
  return count;
}

// The axis, end to end, swept by the radius: the side, where another body's edge crosses it; and the rims' chords,
// each with the cap's normal and the side's at its middle as its faces.
int contact_edges(const Shape& shape, ContactEdges& edges) {
  static_assert(1 + 2 * kPerRim <= kMaxContactEdges);
  edges[0] = {Eigen::Vector3d(0.0, 0.0, -0.5 * shape.length_m), Eigen::Vector3d(0.0, 0.0, 0.5 * shape.length_m),
              shape.radius_m};
  int count = 1;
  for (const double side : {-1.0, 1.0}) {
    const double z_m = 0.5 * side * shape.length_m;
    for (int k = 0; k < kPerRim; ++k) {
      const double middle = 2.0 * std::numbers::pi * (k + 0.5) / kPerRim;
      edges[static_cast<std::size_t>(count++)] = {rim_point(shape, k, z_m), rim_point(shape, k + 1, z_m), 0.0,
                                                  Eigen::Vector3d(0.0, 0.0, side),
                                                  Eigen::Vector3d(std::cos(middle), std::sin(middle), 0.0)};
    }
  }
  return count;
}

constexpr std::string_view kKeys[] = {"radius_m", "length_m"};

}  // namespace

const ShapeKindOps kCylinderOps{
    .name = "cylinder",
    .traits = {.carries_axes = true, .flat_faces = false, .round = false, .normal_through_core = false, .convex = true},
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
