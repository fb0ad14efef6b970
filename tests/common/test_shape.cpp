// SPDX-License-Identifier: Apache-2.0
#include "world_manager/features/body_geometry.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

using impetus::BodyPose;
using impetus::Shape;
using impetus::ShapeKind;
using impetus::SurfacePoint;
using Eigen::Vector3d;

namespace {

// Rounding in a rotation and back is a few ulps of the 0.1 m scale.
constexpr double kTolerance_m = 1e-12;

Shape box(double x, double y, double z) {
  Shape s;
  s.kind = ShapeKind::box;
  s.box_size_m = {x, y, z};
  return s;
}
Shape round_shape(ShapeKind kind, double radius_m, double length_m = 0.0) {
  Shape s;
  s.kind = kind;
  s.radius_m = radius_m;
  s.length_m = length_m;
  return s;
}

void check(const SurfacePoint& got, const Vector3d& point_m, const Vector3d& normal, double signed_distance_m) {
  INFO("point " << got.point_m.transpose() << " normal " << got.normal.transpose() << " d " << got.signed_distance_m);
  CHECK((got.point_m - point_m).norm() < kTolerance_m);
  CHECK((got.normal - normal).norm() < kTolerance_m);
  CHECK(got.signed_distance_m == Approx(signed_distance_m).margin(kTolerance_m));
}

}  // namespace

TEST_CASE("box: nearest point outside a face, an edge and a corner") {
  const Shape b = box(0.2, 0.4, 0.6);  // half extents 0.1, 0.2, 0.3
  check(impetus::nearest_surface_point_body(b, {0.15, 0.05, 0.0}), {0.1, 0.05, 0.0}, {1, 0, 0}, 0.05);
  check(impetus::nearest_surface_point_body(b, {0.13, 0.24, 0.0}), {0.1, 0.2, 0.0},
        Vector3d(0.03, 0.04, 0).normalized(), 0.05);
  check(impetus::nearest_surface_point_body(b, {-0.2, -0.3, 0.4}), {-0.1, -0.2, 0.3},
        Vector3d(-1, -1, 1).normalized(), std::sqrt(0.03));
}

TEST_CASE("box: on the surface and inside pick the nearest face, not the far side") {
  const Shape b = box(0.2, 0.4, 0.6);
  check(impetus::nearest_surface_point_body(b, {0.1, 0.0, 0.0}), {0.1, 0.0, 0.0}, {1, 0, 0}, 0.0);
  // Just inside the −x face: the −x face is 1 cm away, every other face farther.
  check(impetus::nearest_surface_point_body(b, {-0.09, 0.05, 0.1}), {-0.1, 0.05, 0.1}, {-1, 0, 0}, -0.01);
  // Deep inside near the top: +z face is the nearest (gap 0.02 < 0.1 in x).
  check(impetus::nearest_surface_point_body(b, {0.0, 0.0, 0.28}), {0.0, 0.0, 0.3}, {0, 0, 1}, -0.02);
}

TEST_CASE("sphere: radial normal outside, inside and a fixed direction at the centre") {
  const Shape s = round_shape(ShapeKind::sphere, 0.1);
  check(impetus::nearest_surface_point_body(s, {0.3, 0.0, 0.4}), {0.06, 0.0, 0.08}, {0.6, 0, 0.8}, 0.4);
  check(impetus::nearest_surface_point_body(s, {0.0, -0.05, 0.0}), {0.0, -0.1, 0.0}, {0, -1, 0}, -0.05);
  check(impetus::nearest_surface_point_body(s, {0.0, 0.0, 0.0}), {0.0, 0.0, 0.1}, {0, 0, 1}, -0.1);
}

TEST_CASE("capsule: side, cap and inside") {
  const Shape c = round_shape(ShapeKind::capsule, 0.05, 0.2);  // cap centres at z = ±0.1
  check(impetus::nearest_surface_point_body(c, {0.15, 0.0, 0.05}), {0.05, 0.0, 0.05}, {1, 0, 0}, 0.1);
  check(impetus::nearest_surface_point_body(c, {0.0, 0.0, 0.3}), {0.0, 0.0, 0.15}, {0, 0, 1}, 0.15);
  check(impetus::nearest_surface_point_body(c, {0.0, 0.03, -0.05}), {0.0, 0.05, -0.05}, {0, 1, 0}, -0.02);
  check(impetus::nearest_surface_point_body(c, {0.0, 0.0, 0.0}), {0.05, 0.0, 0.0}, {1, 0, 0}, -0.05);
}

TEST_CASE("cylinder: side, cap, rim and inside") {
  const Shape c = round_shape(ShapeKind::cylinder, 0.05, 0.2);  // caps at z = ±0.1
  check(impetus::nearest_surface_point_body(c, {0.0, -0.15, 0.0}), {0.0, -0.05, 0.0}, {0, -1, 0}, 0.1);
  check(impetus::nearest_surface_point_body(c, {0.01, 0.0, 0.2}), {0.01, 0.0, 0.1}, {0, 0, 1}, 0.1);
  check(impetus::nearest_surface_point_body(c, {0.08, 0.0, 0.14}), {0.05, 0.0, 0.1}, {0.6, 0, 0.8}, 0.05);
  // Inside, 1 cm below the top cap and 4 cm from the side: the cap is nearer.
  check(impetus::nearest_surface_point_body(c, {0.01, 0.0, 0.09}), {0.01, 0.0, 0.1}, {0, 0, 1}, -0.01);
  // Inside, 1 cm from the side: the side is nearer.
  check(impetus::nearest_surface_point_body(c, {0.0, 0.04, 0.0}), {0.0, 0.05, 0.0}, {0, 1, 0}, -0.01);
}

TEST_CASE("rotated and translated bodies give world-frame points and normals") {
  BodyPose pose;
  pose.position_m = {1.0, 2.0, 3.0};
  pose.orientation = Eigen::AngleAxisd(std::numbers::pi / 2, Vector3d::UnitZ());  // body x → world y
  const Shape b = box(0.2, 0.4, 0.6);
  // A point 5 cm beyond the body +x face is at world (1, 2 + 0.15, 3).
  check(impetus::nearest_surface_point(b, pose, {1.0, 2.15, 3.0}), {1.0, 2.1, 3.0}, {0, 1, 0}, 0.05);
  // Inside, near the body −y face (world +x).
  check(impetus::nearest_surface_point(b, pose, {1.19, 2.0, 3.0}), {1.2, 2.0, 3.0}, {1, 0, 0}, -0.01);

  BodyPose tilted;
  tilted.orientation = Eigen::AngleAxisd(std::numbers::pi / 2, Vector3d::UnitX());  // body z → world −y
  const Shape c = round_shape(ShapeKind::capsule, 0.05, 0.2);
  check(impetus::nearest_surface_point(c, tilted, {0.0, -0.3, 0.0}), {0.0, -0.15, 0.0}, {0, -1, 0}, 0.15);
}

TEST_CASE("world bounds contain the surface points of rotated shapes and are tight for axis-aligned ones") {
  BodyPose pose;
  pose.position_m = {0.1, -0.2, 0.3};
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()));
  for (const Shape& shape : {box(0.1, 0.2, 0.3), round_shape(ShapeKind::sphere, 0.1),
                             round_shape(ShapeKind::capsule, 0.05, 0.2), round_shape(ShapeKind::cylinder, 0.05, 0.2)}) {
    const Eigen::AlignedBox3d bounds = impetus::world_bounds(shape, pose);
    // Project from far away in many directions: each nearest surface point must lie in the box.
    for (int i = 0; i < 200; ++i) {
      const Vector3d direction = Vector3d(std::sin(i * 1.3), std::cos(i * 0.7), std::sin(i * 2.1 + 1)).normalized();
      const SurfacePoint s = impetus::nearest_surface_point(shape, pose, pose.position_m + 10.0 * direction);
      CHECK(bounds.exteriorDistance(s.point_m) < kTolerance_m);
    }
  }
  const Eigen::AlignedBox3d tight = impetus::world_bounds(box(0.1, 0.2, 0.3), BodyPose{});
  CHECK((tight.max() - Vector3d(0.05, 0.1, 0.15)).norm() < kTolerance_m);
}
