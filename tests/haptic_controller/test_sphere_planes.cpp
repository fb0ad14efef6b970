// SPDX-License-Identifier: Apache-2.0
// A sphere's plane is taken again at the proxy every tick (sphere_planes.h); its push turns nothing.

#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/sphere_planes.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

namespace {

// A ball of radius 1 cm at `centre`, its tangent plane at its top (where the world saw the finger).
ContactPlane ball_plane(const Vector3d& centre, int id = 4) {
  ContactPlane plane = make_plane(centre + Vector3d(0, 0, 0.01), {0, 0, 1}, id, true);
  plane.flags |= kPlaneSphere;
  plane.extent_m = 0.01;
  plane.com_m = centre;
  return plane;
}

}  // namespace

TEST_CASE("sphere planes: the tangent plane at the point nearest the proxy, same centre and radius") {
  const Vector3d centre(0.1, 0.0, 0.01);
  PlaneSet planes = make_set({ball_plane(centre), make_plane({0, 0, 0}, {0, 0, 1}, 9, false)});
  const Vector3d proxy = centre + Vector3d(0.02, 0.0, 0.0);  // beside the ball, at its equator
  retake_sphere_planes(planes, proxy);
  REQUIRE((planes.planes[0].normal - Vector3d::UnitX()).norm() < 1e-15);
  REQUIRE((planes.planes[0].point_m - (centre + Vector3d(0.01, 0, 0))).norm() < 1e-15);
  REQUIRE((planes.planes[0].point_m - planes.planes[0].extent_m * planes.planes[0].normal - centre).norm() < 1e-15);
  // Not a sphere: untouched.
  REQUIRE(planes.planes[1].normal == Vector3d::UnitZ());
  REQUIRE(planes.planes[1].point_m == Vector3d::Zero());
  // The proxy at the centre: no direction, the plane stays.
  const ContactPlane before = planes.planes[0];
  retake_sphere_planes(planes, centre);
  REQUIRE(planes.planes[0].normal == before.normal);
}

TEST_CASE("sphere planes: a push along the normal turns nothing, wherever the proxy sits on the tangent plane") {
  const Vector3d centre(0.0, 0.0, 0.01);
  const ContactPlane plane = ball_plane(centre);
  // The proxy held 6 mm off the tangent point (an edge with another plane), pushed straight down: through the centre.
  const Vector3d proxy = plane.point_m + Vector3d(0.006, 0.0, 0.0);
  REQUIRE(plane.angular_impulse_Nms(proxy, Vector3d(0, 0, -0.002)).norm() < 1e-18);
  // Friction along the surface does turn it: 1 mN·s at 1 cm above the centre.
  const Vector3d turned = plane.angular_impulse_Nms(plane.point_m, Vector3d(0.001, 0, 0));
  REQUIRE((turned - Vector3d(0, 1e-5, 0)).norm() < 1e-15);
  // A flat face keeps the lever of the proxy.
  ContactPlane face = plane;
  face.flags &= ~kPlaneSphere;
  REQUIRE(face.angular_impulse_Nms(proxy, Vector3d(0, 0, -0.002)).norm() > 1e-6);
}
