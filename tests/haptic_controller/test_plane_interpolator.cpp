// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/plane_interpolator.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace impetus;
using impetus::test::make_frame;
using impetus::test::wire_plane;
using Eigen::Vector3d;

namespace {
// Where the planes turn about: on the line through the points (0,0,0) and (0.01,0,0.02) of the first test, whose
// frames' planes both pass near it, so the paper's rule and the pivot rule coincide there.
const Vector3d kPivot = Vector3d::Zero();
}  // namespace

TEST_CASE("interpolation weight is the elapsed fraction of the world period, clamped") {
  REQUIRE(interpolation_weight(1.0, 1.0, 0.05) == 0.0);
  REQUIRE(interpolation_weight(1.025, 1.0, 0.05) == Approx(0.5));
  REQUIRE(interpolation_weight(1.2, 1.0, 0.05) == 1.0);
  REQUIRE(interpolation_weight(0.9, 1.0, 0.05) == 0.0);
  REQUIRE(interpolation_weight(1.0, 1.0, 0.0) == 1.0);
  REQUIRE(interpolation_weight(std::numeric_limits<double>::quiet_NaN(), 1.0, 0.05) == 1.0);
  // Lockstep: now = tick · 1 ms exactly, n = 50 ticks per world step: w = ticks since arrival / n.
  for (int j = 0; j <= 50; ++j) REQUIRE(interpolation_weight(0.1 + j * 1e-3, 0.1, 0.05) == Approx(j / 50.0));
}

TEST_CASE("planes are blended between frames i−1 and i (paper 3.2), normals renormalised") {
  const PlaneFrame previous = make_frame({wire_plane(7, {0, 0, 0}, {0, 0, 1})}, 0);
  const PlaneFrame current = make_frame({wire_plane(7, {0.01, 0, 0.02}, {1, 0, 1})}, 1);
  PlaneSet out;
  interpolate_planes(previous, current, 0.0, kPivot, out);
  REQUIRE(out.count == 1);
  REQUIRE((out.planes[0].point_m - Vector3d::Zero()).norm() < 1e-15);
  REQUIRE((out.planes[0].normal - Vector3d::UnitZ()).norm() < 1e-15);
  interpolate_planes(previous, current, 0.25, kPivot, out);
  const Vector3d blend = 0.75 * Vector3d::UnitZ() + 0.25 * Vector3d(1, 0, 1).normalized();
  REQUIRE((out.planes[0].normal - blend.normalized()).norm() < 1e-15);
  REQUIRE(out.planes[0].normal.norm() == Approx(1.0).epsilon(1e-15));
  // The pivot's signed distance moves linearly: 0 from frame i−1's plane, −0.03/√2 m from frame i's.
  const double offset = out.planes[0].normal.dot(kPivot - out.planes[0].point_m);
  REQUIRE(offset == Approx(0.25 * -0.03 / std::sqrt(2.0)).epsilon(1e-12));
  // The point keeps its place along the surface: it differs from the paper's blended point only along the normal.
  const Vector3d moved = out.planes[0].point_m - Vector3d(0.0025, 0, 0.005);
  REQUIRE((moved - moved.dot(out.planes[0].normal) * out.planes[0].normal).norm() < 1e-15);
  interpolate_planes(previous, current, 1.0, kPivot, out);
  REQUIRE((out.planes[0].point_m - Vector3d(0.01, 0, 0.02)).norm() < 1e-15);
  interpolate_planes(previous, current, 7.0, kPivot, out);  // clamped
  REQUIRE((out.planes[0].point_m - Vector3d(0.01, 0, 0.02)).norm() < 1e-15);
}

TEST_CASE("planes are matched by object id, not by position in the frame, new objects start at frame i") {
  const PlaneFrame previous =
      make_frame({wire_plane(1, {0, 0, 0}, {0, 0, 1}), wire_plane(2, {0.1, 0, 0}, {1, 0, 0})}, 0);
  PlaneFrame current = make_frame({wire_plane(2, {0.2, 0, 0}, {1, 0, 0}), wire_plane(3, {0, 0.3, 0}, {0, 1, 0}),
                                   wire_plane(1, {0, 0, 0.04}, {0, 0, 1})},
                                  1);
  current.planes[0].velocity_mps = {1.0, 2.0, 3.0};
  current.planes[0].static_friction = 0.7;
  PlaneSet out;
  interpolate_planes(previous, current, 0.5, kPivot, out);
  REQUIRE(out.count == 3);
  REQUIRE(out.planes[0].object_id == 2);
  REQUIRE(out.planes[0].point_m.x() == Approx(0.15));
  REQUIRE(out.planes[0].velocity_mps == Vector3d(1.0, 2.0, 3.0));  // velocities and friction are frame i's
  REQUIRE(out.planes[0].static_friction == 0.7);
  REQUIRE(out.planes[1].object_id == 3);
  REQUIRE(out.planes[1].point_m.y() == 0.3);  // appeared in frame i: no sweep from anywhere
  REQUIRE(out.planes[2].object_id == 1);
  REQUIRE(out.planes[2].point_m.z() == Approx(0.02));
  REQUIRE(out.planes[2].com_m.z() == Approx(0.02 - 0.025));
}

TEST_CASE("a flipped normal switches planes at the midpoint instead of sweeping through the object") {
  const PlaneFrame previous = make_frame({wire_plane(5, {0, 0, 0.01}, {0, 0, 1})}, 0);
  const PlaneFrame current = make_frame({wire_plane(5, {0, 0, -0.01}, {0, 0, -1})}, 1);
  PlaneSet out;
  for (int j = 0; j <= 50; ++j) {
    const double w = j / 50.0;
    interpolate_planes(previous, current, w, kPivot, out);
    REQUIRE(out.planes[0].normal.allFinite());
    REQUIRE(out.planes[0].normal.norm() == Approx(1.0));
    const bool newer = w >= 0.5;
    REQUIRE(out.planes[0].normal.z() == (newer ? -1.0 : 1.0));
    REQUIRE(out.planes[0].point_m.z() == (newer ? -0.01 : 0.01));
  }
}

TEST_CASE("normals 90 degrees apart blend without vanishing") {
  const PlaneFrame previous = make_frame({wire_plane(5, {0, 0, 0}, {0, 0, 1})}, 0);
  const PlaneFrame current = make_frame({wire_plane(5, {0, 0, 0}, {1, 0, 0})}, 1);
  PlaneSet out;
  interpolate_planes(previous, current, 0.5, kPivot, out);
  REQUIRE((out.planes[0].normal - Vector3d(1, 0, 1).normalized()).norm() < 1e-15);
  // Nearly antiparallel: still a clean switch, never a near-zero normal.
  const PlaneFrame almost = make_frame({wire_plane(5, {0, 0, 0}, {1e-12, 0, -1})}, 1);
  interpolate_planes(previous, almost, 0.5, kPivot, out);
  REQUIRE(out.planes[0].normal.allFinite());
  REQUIRE(out.planes[0].normal.norm() == Approx(1.0));
}

TEST_CASE("a plane that turns at a box's edge turns about the proxy: no drop at the finger (hard case 6)") {
  // Frame i−1: the box's top face, its point 15 mm behind the finger. Frame i: the edge the finger slid past.
  const PlaneFrame previous = make_frame({wire_plane(1, {0.065, 0, 0.05}, {0, 0, 1})}, 0);
  const PlaneFrame current = make_frame({wire_plane(1, {0.075, 0, 0.05}, {1, 0, 0})}, 1);
  const Vector3d proxy(0.080, 0, 0.0499);  // 0.1 mm into the top face, 5 mm beyond the edge
  PlaneSet out;
  double last = -0.0001;
  for (int j = 0; j <= 50; ++j) {
    interpolate_planes(previous, current, j / 50.0, proxy, out);
    const double distance = out.planes[0].normal.dot(proxy - out.planes[0].point_m);
    // From −0.1 mm to +5 mm in equal steps: the face lets go of the finger smoothly, never pulling it in.
    REQUIRE(distance == Approx(-0.0001 + (j / 50.0) * 0.0051).margin(1e-12));
    REQUIRE(distance >= last - 1e-15);
    last = distance;
  }
}

TEST_CASE("a box whose face flips between frames moves with its body whichever face is shown") {
  // A 2 cm box moving 5 mm along +x in a period toward a proxy beside its +x face; in frame i the proxy is past the
  // top's rim and the world sent the top. Frame i−1's face is shown until the midpoint, but carried with the box:
  // held where frame i−1 left it, the box would close over the proxy for half a period.
  auto box_plane = [](double x_m, const Vector3d& point, const Vector3d& normal) {
    Plane plane = wire_plane(5, point, normal);
    plane.com_m = {x_m, 0.0, 0.0};
    impetus::test::set_shape(plane, impetus::test::box_shape(Vector3d::Constant(0.01)));
    return plane;
  };
  const PlaneFrame previous = make_frame({box_plane(0.0, {0.01, 0.0, 0.0}, {1, 0, 0})}, 0);
  const PlaneFrame current = make_frame({box_plane(0.005, {0.012, 0.0, 0.01}, {-0.2, 0, 1})}, 1);
  PlaneSet out;
  for (const double w : {0.0, 0.25, 0.49, 0.5, 0.75, 1.0}) {
    interpolate_planes(previous, current, w, kPivot, out);
    const ContactPlane& plane = out.planes[0];
    CHECK(plane.com_m.x() == Approx(0.005 * w).margin(1e-15));
    if (w < 0.5) {
      CHECK(plane.normal.isApprox(Vector3d(1, 0, 0)));
      CHECK(plane.point_m.isApprox(Vector3d(0.01 + 0.005 * w, 0.0, 0.0)));
    } else {
      CHECK(plane.normal.isApprox(Vector3d(-0.2, 0, 1).normalized()));
      CHECK(plane.point_m.isApprox(Vector3d(0.012 - 0.005 * (1.0 - w), 0.0, 0.01)));
    }
  }
}
