// SPDX-License-Identifier: Apache-2.0
#include "common/shape/shape.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

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

namespace {

// One shape of every kind, sized so that none is degenerate.
std::vector<Shape> every_kind() {
  return {box(0.1, 0.2, 0.3), round_shape(ShapeKind::sphere, 0.1), round_shape(ShapeKind::capsule, 0.05, 0.2),
          round_shape(ShapeKind::cylinder, 0.05, 0.2)};
}

}  // namespace

TEST_CASE("every kind has a name that reads back, its own keys, a volume, an inertia and an extent, and kind none "
          "has none") {
  std::string names;
  for (std::uint32_t k = 1; k < impetus::kShapeKindCount; ++k) {
    const auto kind = static_cast<ShapeKind>(k);
    ShapeKind read = ShapeKind::none;
    REQUIRE(impetus::shape_kind_from_string(impetus::to_string(kind), read));
    CHECK(read == kind);
    CHECK_FALSE(impetus::shape_keys(kind).empty());
    CHECK(impetus::shape_kind_names().find(impetus::to_string(kind)) != std::string::npos);
  }
  for (const Shape& shape : every_kind()) {
    INFO(impetus::to_string(shape.kind));
    CHECK(impetus::volume_m3(shape) > 0.0);
    CHECK(impetus::inertia_kgm2(shape, 1.0).diagonal().minCoeff() > 0.0);
    CHECK(impetus::plane_extent_m(shape) > 0.0);
    CHECK(impetus::describes_within_m(shape) >= impetus::plane_extent_m(shape));
    CHECK(impetus::shape_problem(shape) == nullptr);
  }
  ShapeKind read = ShapeKind::box;
  CHECK_FALSE(impetus::shape_kind_from_string("none", read));
  CHECK_FALSE(impetus::shape_kind_from_string("Box", read));
  CHECK(impetus::shape_kind_names() == "box, sphere, capsule, cylinder or mesh");
  const Shape none;
  CHECK(impetus::volume_m3(none) == 0.0);
  CHECK(impetus::plane_extent_m(none) == 0.0);
  CHECK_FALSE(impetus::segment_enters_body(none, Vector3d(-1, 0, 0), Vector3d(1, 0, 0)));
}

TEST_CASE("a mesh this process has not loaded answers as the ball that holds it, one naming no triangles is refused") {
  // The haptic controller and a viewer get a mesh's descriptor from the world, not its triangles
  // (common/shape/mesh_geometry.h): its radius still bounds it, and its planes are used as sent.
  Shape mesh;
  mesh.kind = ShapeKind::mesh;
  mesh.radius_m = 0.04;
  mesh.box_size_m = {0.05, 0.06, 0.07};
  mesh.mesh_hash = 0x1234'5678'9abc'def0ULL;
  CHECK(impetus::shape_problem(mesh) == nullptr);
  CHECK_FALSE(impetus::traits(ShapeKind::mesh).convex);
  const impetus::SurfacePoint above = impetus::nearest_surface_point_body(mesh, Vector3d(0.0, 0.0, 0.1));
  CHECK(above.signed_distance_m == Approx(0.06));
  CHECK(impetus::plane_extent_m(mesh) == Approx(0.08));  // no two of its points are farther apart
  CHECK(impetus::world_bounds(mesh, BodyPose{}).sizes().maxCoeff() == Approx(0.08));
  mesh.mesh_hash = 0;
  CHECK(impetus::shape_problem(mesh) != nullptr);
}

TEST_CASE("a received shape with a size that is not finite, not positive or out of the scene's range is refused") {
  for (const Shape& valid : every_kind()) {
    INFO(impetus::to_string(valid.kind));
    for (const double bad : {0.0, -0.01, std::nan(""), 1e4}) {
      Shape shape = valid;
      if (shape.kind == ShapeKind::box) {
        shape.box_size_m[1] = bad;
      } else {
        shape.radius_m = bad;
      }
      CHECK(impetus::shape_problem(shape) != nullptr);
    }
  }
  Shape ball = round_shape(ShapeKind::capsule, 0.05, 0.0);  // a capsule of no length is a ball: allowed
  CHECK(impetus::shape_problem(ball) == nullptr);
  ball.kind = ShapeKind::cylinder;  // a cylinder needs a length
  CHECK(impetus::shape_problem(ball) != nullptr);
  Shape unknown = box(0.1, 0.1, 0.1);
  unknown.kind = static_cast<ShapeKind>(impetus::kShapeKindCount);
  CHECK(impetus::shape_problem(unknown) != nullptr);
}

TEST_CASE("volume and inertia agree with the shape's own inside test, counted on a grid") {
  // The midpoints of a 100³ grid over the bounding box: each cell inside (nearest surface point behind it) adds its
  // volume and its second moments. The count converges as the cell size (≤ 3 mm here) over the body size, ≤ 1 %.
  for (const Shape& shape : every_kind()) {
    INFO(impetus::to_string(shape.kind));
    const Eigen::AlignedBox3d bounds = impetus::world_bounds(shape, BodyPose{});
    constexpr int kCells = 100;
    const Vector3d cell = bounds.sizes() / kCells;
    const double cell_m3 = cell.prod();
    double volume_m3 = 0.0;
    Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();  // ∫ x xᵀ dV
    for (int i = 0; i < kCells; ++i) {
      for (int j = 0; j < kCells; ++j) {
        for (int k = 0; k < kCells; ++k) {
          const Vector3d x = bounds.min() + cell.cwiseProduct(Vector3d(i + 0.5, j + 0.5, k + 0.5));
          if (impetus::nearest_surface_point_body(shape, x).signed_distance_m >= 0.0) continue;
          volume_m3 += cell_m3;
          second_moment += cell_m3 * x * x.transpose();
        }
      }
    }
    CHECK(volume_m3 == Approx(impetus::volume_m3(shape)).epsilon(0.01));
    // Inertia of a unit mass: (tr(S)·1 − S)/V.
    const Eigen::Matrix3d counted = (second_moment.trace() * Eigen::Matrix3d::Identity() - second_moment) / volume_m3;
    const Eigen::Matrix3d formula = impetus::inertia_kgm2(shape, 1.0);
    for (int a = 0; a < 3; ++a) CHECK(counted(a, a) == Approx(formula(a, a)).epsilon(0.02));
    CHECK((formula - Eigen::Matrix3d(formula.diagonal().asDiagonal())).norm() == 0.0);  // principal axes: the body's
  }
}

TEST_CASE("a segment enters a shape exactly when the shape's distance along it goes below zero") {
  // Random segments through a 0.5 m cube around each shape; the distance sampled at 4000 points along each decides.
  // Samples lie at most 0.22 mm apart and the distance changes no faster than the position, so the sampled least is
  // within 0.11 mm of the true one: segments whose sampled least lies within 0.2 mm of the surface are left out.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.25, 0.25);
  int decided = 0, entering = 0;
  for (const Shape& shape : every_kind()) {
    INFO(impetus::to_string(shape.kind));
    for (int n = 0; n < 300; ++n) {
      const Vector3d from(coordinate(random), coordinate(random), coordinate(random));
      const Vector3d to(coordinate(random), coordinate(random), coordinate(random));
      double least_m = std::numeric_limits<double>::infinity();
      for (int s = 0; s <= 4000; ++s) {
        const Vector3d x = from + (s / 4000.0) * (to - from);
        least_m = std::min(least_m, impetus::nearest_surface_point_body(shape, x).signed_distance_m);
      }
      if (std::abs(least_m) < 2e-4) continue;
      ++decided;
      entering += least_m < 0.0 ? 1 : 0;
      CHECK(impetus::segment_enters_body(shape, from, to) == (least_m < 0.0));
      // Shrunk by a margin larger than the deepest it goes, it no longer enters.
      if (least_m < 0.0) CHECK_FALSE(impetus::segment_enters_body(shape, from, to, -least_m + 2e-4));
    }
  }
  CHECK(decided > 1000);                    // the samples settled most segments
  CHECK(entering > 100);                    // and both answers occur
  CHECK(decided - entering > 100);
}

TEST_CASE("the support function bounds every surface point and is met by one") {
  for (const Shape& shape : every_kind()) {
    INFO(impetus::to_string(shape.kind));
    for (int i = 0; i < 50; ++i) {
      const Vector3d n = Vector3d(std::sin(i * 1.3), std::cos(i * 0.7), std::sin(i * 2.1 + 1)).normalized();
      const double h_m = impetus::support_m(shape, n);
      // The surface point nearest a far point along n is the support point: it meets h(n).
      const SurfacePoint far = impetus::nearest_surface_point_body(shape, 100.0 * n);
      CHECK(n.dot(far.point_m) <= h_m + 1e-12);
      CHECK(n.dot(far.point_m) == Approx(h_m).margin(2e-4));  // the far point is 100 m off: within r²/200 m
      for (int j = 0; j < 50; ++j) {
        const Vector3d d = Vector3d(std::sin(j * 0.9 + 2), std::cos(j * 1.7), std::sin(j * 0.3)).normalized();
        CHECK(n.dot(impetus::nearest_surface_point_body(shape, 10.0 * d).point_m) <= h_m + 1e-12);
      }
    }
  }
}
