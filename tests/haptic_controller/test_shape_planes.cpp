// SPDX-License-Identifier: Apache-2.0
// Spheres' and boxes' planes are taken again at the proxy every tick (shape_planes.h); a push on a sphere along its
// normal turns nothing; a box's face ends at its rim.

#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/plane_interpolator.h"
#include "haptic_controller/proxy_projection.h"
#include "haptic_controller/servo.h"
#include "haptic_controller/shape_planes.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

namespace {

// A ball of radius 1 cm at `centre`, its tangent plane at its top (where the world saw the finger).
ContactPlane ball_plane(const Vector3d& centre, int id = 4) {
  ContactPlane plane = make_plane(centre + Vector3d(0, 0, 0.01), {0, 0, 1}, id, true);
  plane.shape = test::round_shape(ShapeKind::sphere, 0.01);
  plane.extent_m = 0.01;
  plane.com_m = centre;
  return plane;
}

}  // namespace

TEST_CASE("sphere planes: the tangent plane at the point nearest the proxy, same centre and radius") {
  const Vector3d centre(0.1, 0.0, 0.01);
  PlaneSet planes = make_set({ball_plane(centre), make_plane({0, 0, 0}, {0, 0, 1}, 9, false)});
  const Vector3d proxy = centre + Vector3d(0.02, 0.0, 0.0);  // beside the ball, at its equator
  retake_shape_planes(planes, proxy);
  REQUIRE((planes.planes[0].normal - Vector3d::UnitX()).norm() < 1e-15);
  REQUIRE((planes.planes[0].point_m - (centre + Vector3d(0.01, 0, 0))).norm() < 1e-15);
  REQUIRE((planes.planes[0].point_m - planes.planes[0].extent_m * planes.planes[0].normal - centre).norm() < 1e-15);
  // Not a sphere: untouched.
  REQUIRE(planes.planes[1].normal == Vector3d::UnitZ());
  REQUIRE(planes.planes[1].point_m == Vector3d::Zero());
  // The proxy at the centre: no direction, the plane stays.
  const ContactPlane before = planes.planes[0];
  retake_shape_planes(planes, centre);
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
  face.shape = Shape{};
  REQUIRE(face.angular_impulse_Nms(proxy, Vector3d(0, 0, -0.002)).norm() > 1e-6);
}

namespace {

// A static 10 cm box centred at `centre`, turned by `turn`, and the plane of its top face (body +z) as the world
// sends it: at the point of the face under `query`.
Plane box_top_plane(const Vector3d& centre, const Eigen::Quaterniond& turn, const Vector3d& query) {
  const Eigen::Matrix3d axes = turn.toRotationMatrix();
  const Vector3d half(0.05, 0.05, 0.05);
  Vector3d local = axes.transpose() * (query - centre);
  local.z() = half.z();
  Plane plane = test::wire_plane(3, centre + axes * local, axes.col(2), false);
  plane.com_m = to_vec3(centre);
  test::set_shape(plane, test::box_shape(half), axes);
  return plane;
}

}  // namespace

TEST_CASE("box planes: a face's plane stays over the face, past its rim the box's nearest edge, corner or face") {
  const Vector3d centre(0.01, -0.02, 0.05);
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    const ContactPlane top = to_contact_plane(box_top_plane(centre, turn, at(0.0, 0.0, 0.06)));
    REQUIRE(top.shape.kind == ShapeKind::box);
    const auto retaken = [&](const Vector3d& proxy) {
      PlaneSet planes = make_set({top});
      retake_shape_planes(planes, proxy);
      return planes.planes[0];
    };
    // Over the face, on the rim (to rounding), and inside the box: the plane as it came.
    for (const Vector3d& proxy : {at(0.03, -0.04, 0.05), at(0.05 + 1e-12, 0.0, 0.05), at(0.0, 0.01, 0.02)}) {
      const ContactPlane same = retaken(proxy);
      CHECK(same.normal == top.normal);
      CHECK(same.point_m == top.point_m);
    }
    // Past the +x rim, above the top: the edge, its normal from the edge to the proxy.
    const ContactPlane edge = retaken(at(0.053, 0.01, 0.054));
    CHECK((edge.point_m - at(0.05, 0.01, 0.05)).norm() < 1e-15);
    CHECK((edge.normal - axes * Vector3d(0.6, 0, 0.8)).norm() < 1e-12);  // (3, 0, 4) mm from the edge
    // Round the edge, beside the +x face below the top: that face.
    const ContactPlane side = retaken(at(0.052, 0.01, 0.03));
    CHECK((side.normal - axes.col(0)).norm() < 1e-12);
    CHECK((side.point_m - at(0.05, 0.01, 0.03)).norm() < 1e-15);
    // Past a corner: the corner.
    const ContactPlane corner = retaken(at(0.06, -0.06, 0.06));
    CHECK((corner.point_m - at(0.05, -0.05, 0.05)).norm() < 1e-15);
    CHECK((corner.normal - axes * Vector3d(1, -1, 1).normalized()).norm() < 1e-12);
    // Friction, the object and its state are the plane's own.
    CHECK(edge.object_id == top.object_id);
    CHECK(edge.static_friction == top.static_friction);
  }
}

TEST_CASE("box planes: between world frames a finger that slides off an edge is let go at once, and round the "
          "edge it meets the side face") {
  // One world frame (the top face of a static box, 20 Hz) and a finger that, within that period, slides along the
  // top 3 mm deep, passes the +x edge, goes down beside the box and presses 3 mm into the +x face. The world's next
  // frame would fix the planes 50 ms later; the servo must not wait for it.
  const Vector3d centre(0.0, 0.0, 0.0);
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Vector3d::UnitZ()));
  const Eigen::Matrix3d axes = turn.toRotationMatrix();
  const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
  ServoOptions options;
  HapticServo servo(options, 5);
  servo.on_plane_frame(test::make_frame({box_top_plane(centre, turn, at(0.0, 0.0, 0.06))}), 0.0);
  // Waypoints (box frame, m) and the ticks between them; 1 kHz ticks, all within 46 ms.
  const std::array<std::pair<Vector3d, int>, 6> path{{{{0.0, 0.0, 0.06}, 0},      // above the top
                                                      {{0.0, 0.0, 0.047}, 6},     // 3 mm into it
                                                      {{0.054, 0.0, 0.047}, 20},  // along it, past the edge
                                                      {{0.054, 0.0, 0.02}, 10},   // down beside the box
                                                      {{0.047, 0.0, 0.02}, 6},    // 3 mm into the +x face
                                                      {{0.047, 0.0, 0.02}, 3}}};  // held there
  int tick = 0;
  std::vector<Vector3d> fingers, proxies, forces;
  for (std::size_t leg = 1; leg < path.size(); ++leg) {
    for (int k = 1; k <= path[leg].second; ++k) {
      const double s = static_cast<double>(k) / path[leg].second;
      FingerSample finger;
      finger.position_m = at(0, 0, 0) + axes * ((1.0 - s) * path[leg - 1].first + s * path[leg].first);
      finger.valid = true;
      ++tick;
      const TickResult& r = servo.tick(&finger, tick * 1e-3, 1e-3);
      fingers.push_back(axes.transpose() * (finger.position_m - centre));
      proxies.push_back(axes.transpose() * (to_eigen(r.proxy_m) - centre));
      forces.push_back(axes.transpose() * to_eigen(r.force_N));
    }
  }
  REQUIRE(tick < 50);  // all within the world period: no second frame was needed
  int first_beyond = -1, last_force = -1;
  for (std::size_t j = 0; j < fingers.size(); ++j) {
    // The proxy never enters the box (beyond rounding).
    CHECK((proxies[j].cwiseAbs() - Vector3d::Constant(0.05)).maxCoeff() > -1e-9);
    if (first_beyond < 0 && fingers[j].x() > 0.05) first_beyond = static_cast<int>(j);
    if (first_beyond < 0 || fingers[j].z() > 0.03) {
      if (forces[j].norm() > 1e-9) last_force = static_cast<int>(j);
    }
  }
  REQUIRE(first_beyond > 0);
  // Let go within two ticks of the finger passing the edge (the face's plane used to last the whole period).
  CHECK(last_force - first_beyond <= 1);
  // Held 3 mm into the side face: pushed out along +x by K·3 mm (the scene's default K, 2000 N/m; at rest the damper
  // adds nothing), nothing along z (no ghost of the top face).
  const Vector3d final_force = forces.back();
  CHECK(final_force.x() == Approx(2000.0 * 0.003).epsilon(1e-6));
  CHECK(std::abs(final_force.z()) < 1e-9);
  CHECK(proxies.back().x() == Approx(0.05).margin(1e-12));
}

namespace {

// A capsule of radius 1 cm, 6 cm between its cap centres, its axis along the turned body z, lying at `centre`; its
// plane as the world gave it for a query above its middle.
Plane capsule_plane(const Vector3d& centre, const Eigen::Quaterniond& turn) {
  const Eigen::Matrix3d axes = turn.toRotationMatrix();
  const Vector3d up = axes.col(0);  // the body x: square to the axis
  Plane plane = test::wire_plane(6, centre + 0.01 * up, up, false);
  plane.com_m = to_vec3(centre);
  test::set_shape(plane, test::round_shape(ShapeKind::capsule, 0.01, 0.06), axes);
  return plane;
}

}  // namespace

TEST_CASE("capsule planes: the tangent plane about the axis point nearest the proxy, along the side and round the "
          "caps, in any orientation") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(0.02, -0.01, 0.03);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    ContactPlane plane = to_contact_plane(capsule_plane(centre, turn));
    REQUIRE(plane.shape.kind == ShapeKind::capsule);
    PlaneSet planes = make_set({plane});
    // Beside the side, 2 cm along the axis from the middle: the side's plane there, not the middle's.
    retake_shape_planes(planes, at(0.0, 0.015, 0.02));
    CHECK((planes.planes[0].normal - axes.col(1)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.0, 0.01, 0.02)).norm() < 1e-12);
    // Beyond an end, off the axis: the cap's sphere about the cap centre.
    const Vector3d beyond = at(0.01, 0.0, 0.04);
    retake_shape_planes(planes, beyond);
    const Vector3d cap_centre = at(0.0, 0.0, 0.03);
    CHECK((planes.planes[0].normal - (beyond - cap_centre).normalized()).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - (cap_centre + 0.01 * (beyond - cap_centre).normalized())).norm() < 1e-12);
    // A push along the normal at a cap turns the capsule about its centre (its line of action misses the CoM); one
    // straight into the side at the middle does not.
    const Vector3d push = -0.002 * planes.planes[0].normal;
    CHECK(planes.planes[0].angular_impulse_Nms(planes.planes[0].point_m, push).norm() > 1e-6);
    retake_shape_planes(planes, at(0.02, 0.0, 0.0));
    CHECK(planes.planes[0].angular_impulse_Nms(planes.planes[0].point_m, -0.002 * planes.planes[0].normal).norm() <
          1e-17);
    // On the axis: no direction, the plane stays.
    const ContactPlane before = planes.planes[0];
    retake_shape_planes(planes, at(0.0, 0.0, 0.01));
    CHECK(planes.planes[0].normal == before.normal);
  }
}

TEST_CASE("capsule planes: between world frames a finger that slides off a capsule's end is let go as it leaves, and "
          "it follows the cap down") {
  // A capsule lying along x on the floor (axis at z = 1 cm, cap centres at x = ±3 cm), one world frame with its plane
  // at the top of its middle, and a finger that within that period presses 2 mm into the top and slides along x past
  // the +x cap.
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()));  // body z along world x
  const Vector3d centre(0.0, 0.0, 0.01);
  Plane world_plane = capsule_plane(centre, turn);
  world_plane.point_m = to_vec3(centre + Vector3d(0, 0, 0.01));
  world_plane.normal = {0.0, 0.0, 1.0};
  ServoOptions options;
  HapticServo servo(options, 5);
  servo.on_plane_frame(test::make_frame({world_plane}), 0.0);
  int tick = 0;
  double last_force_x_m = -1.0, max_force_N = 0.0;
  for (int k = 0; k <= 40; ++k) {
    // From above the top, 2 mm into it over 5 ticks (a finger that starts inside is not pushed out), then along x out
    // to x = 7 cm.
    FingerSample finger;
    finger.position_m = k <= 5 ? Vector3d(-0.01, 0.0, 0.03 - 0.012 * k / 5.0)
                               : Vector3d(-0.01 + 0.08 * (k - 5) / 35.0, 0.0, 0.018);
    finger.valid = true;
    ++tick;
    const TickResult& r = servo.tick(&finger, tick * 1e-3, 1e-3);
    const Vector3d force = to_eigen(r.force_N);
    const Vector3d proxy = to_eigen(r.proxy_m);
    max_force_N = std::max(max_force_N, force.norm());
    if (force.norm() > 1e-9) last_force_x_m = finger.position_m.x();
    // The proxy never enters the capsule (beyond rounding): its distance from the axis segment is at least the radius.
    const double along_m = std::clamp(proxy.x(), -0.03, 0.03);
    CHECK((proxy - Vector3d(along_m, 0.0, 0.01)).norm() > 0.01 - 1e-9);
  }
  REQUIRE(tick < 50);  // all within one world period
  CHECK(max_force_N > 1.0);
  // The finger 18 mm up leaves the cap's sphere (radius 1 cm about x = 3 cm, z = 1 cm) at x = 3 cm + √(1e-4 − 0.8²e-4)
  // = 3.6 cm; with the face's plane it would have been pressed until the next frame.
  CHECK(last_force_x_m < 0.036 + 0.002);
  CHECK(last_force_x_m > 0.03);
}

namespace {

// A cylinder of radius 2 cm and length 6 cm standing on end (axis along the turned body z) at `centre`, its plane the
// top cap's where the world saw the finger, above the middle.
ContactPlane cylinder_top_plane(const Vector3d& centre, const Eigen::Quaterniond& turn) {
  const Eigen::Matrix3d axes = turn.toRotationMatrix();
  Plane plane = test::wire_plane(7, centre + 0.03 * axes.col(2), axes.col(2), false);
  plane.com_m = to_vec3(centre);
  test::set_shape(plane, test::round_shape(ShapeKind::cylinder, 0.02, 0.06), axes);
  return to_contact_plane(plane);
}

}  // namespace

TEST_CASE("cylinder planes: a cap's plane stays over the cap and ends at its rim, the side's follows the proxy") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Vector3d(3, -1, 2).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(-0.01, 0.02, 0.05);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    const ContactPlane top = cylinder_top_plane(centre, turn);
    REQUIRE(top.shape.kind == ShapeKind::cylinder);
    // Over the cap, anywhere within the rim: the plane stays as it came.
    PlaneSet planes = make_set({top});
    retake_shape_planes(planes, at(0.015, -0.005, 0.04));
    CHECK(planes.planes[0].normal == top.normal);
    CHECK(planes.planes[0].point_m == top.point_m);
    // Past the rim, above the cap's level: the rim's nearest point, its normal toward the proxy.
    const Vector3d past = at(0.025, 0.0, 0.032);
    retake_shape_planes(planes, past);
    const Vector3d rim = at(0.02, 0.0, 0.03);
    CHECK((planes.planes[0].point_m - rim).norm() < 1e-12);
    CHECK((planes.planes[0].normal - (past - rim).normalized()).norm() < 1e-12);
    // Beside the side, below the cap: the side's tangent plane there.
    planes = make_set({top});
    retake_shape_planes(planes, at(0.0, 0.03, 0.01));
    CHECK((planes.planes[0].normal - axes.col(1)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.0, 0.02, 0.01)).norm() < 1e-12);
    // A side's plane beside the side: taken again under the proxy as it moves round.
    retake_shape_planes(planes, at(-0.03, 0.0, -0.02));
    CHECK((planes.planes[0].normal + axes.col(0)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(-0.02, 0.0, -0.02)).norm() < 1e-12);
    // Inside: the side the plane faces, its point on the side at the proxy's height.
    const ContactPlane before = planes.planes[0];
    retake_shape_planes(planes, at(0.0, 0.0, 0.005));
    CHECK((planes.planes[0].normal - before.normal).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(-0.02, 0.0, 0.005)).norm() < 1e-12);
  }
}

TEST_CASE("box and cylinder planes: an edge's or a rim's plane from the world becomes the face's over the face, a "
          "face turned by less than a degree stays") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(0.01, -0.02, 0.05);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    // The world took the box's plane with its proxy 3 mm past the +x edge of the top: the edge's plane, tilted 37°.
    ContactPlane edge = to_contact_plane(box_top_plane(centre, turn, at(0.0, 0.0, 0.06)));
    edge.point_m = at(0.05, 0.0, 0.05);
    edge.normal = axes * Vector3d(0.6, 0.0, 0.8);
    // The proxy is now back over the top face, 4 mm in from the edge and 1 mm above the face: the face's own plane,
    // not the edge's, which hangs 3 mm above the face there and would hold a finger that touches nothing.
    PlaneSet planes = make_set({edge});
    retake_shape_planes(planes, at(0.046, 0.01, 0.051));
    CHECK((planes.planes[0].normal - axes.col(2)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.046, 0.01, 0.05)).norm() < 1e-12);

    // A top face the local model turned by half a degree about y: over the face it stays as it is.
    ContactPlane tilted = to_contact_plane(box_top_plane(centre, turn, at(0.0, 0.0, 0.06)));
    tilted.normal = axes * Vector3d(std::sin(0.0087), 0.0, std::cos(0.0087));
    planes = make_set({tilted});
    retake_shape_planes(planes, at(0.02, 0.01, 0.052));
    CHECK(planes.planes[0].normal == tilted.normal);
    CHECK(planes.planes[0].point_m == tilted.point_m);

    // A cylinder's rim plane from the world, the proxy now over the cap: the cap's plane.
    ContactPlane rim = cylinder_top_plane(centre, turn);
    rim.point_m = at(0.02, 0.0, 0.03);
    rim.normal = axes * Vector3d(0.6, 0.0, 0.8);
    planes = make_set({rim});
    retake_shape_planes(planes, at(0.01, 0.005, 0.031));
    CHECK((planes.planes[0].normal - axes.col(2)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.01, 0.005, 0.03)).norm() < 1e-12);
  }
}

TEST_CASE("cylinder planes: on the surface the plane of the part the proxy is on, inside a plane that cuts into the "
          "rim becomes its part's own") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Vector3d(3, -1, 2).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(-0.01, 0.02, 0.05);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    // Between a frame with the rim's plane and one with the side's, the interpolation blends them: a plane tilted 30°
    // off the side's normal toward the axis, through the rim.
    ContactPlane blended = cylinder_top_plane(centre, turn);
    blended.normal = axes * Vector3d(std::cos(0.52), 0.0, std::sin(0.52));
    blended.point_m = at(0.02, 0.0, 0.03);
    // A proxy on the side, 1 cm below the rim: the side's tangent plane there, not the tilt, which leans off the side
    // and would carry the proxy off the surface (a hop each tick as the next one brought it back).
    PlaneSet planes = make_set({blended});
    retake_shape_planes(planes, at(0.02, 0.0, 0.02));
    CHECK((planes.planes[0].normal - axes.col(0)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.02, 0.0, 0.02)).norm() < 1e-12);
    // A proxy inside, under the tilt (the cylinder came at it): pushed out through the side the plane faces.
    // Likewise under a side's plane blended between two frames' tangent planes 36° apart, which lies on their chord,
    // 0.98 mm inside the side here: the side's own plane at the azimuth it faces.
    ContactPlane chord = cylinder_top_plane(centre, turn);
    chord.normal = axes * Vector3d(1, 0, 0);
    chord.point_m = at(0.02 * std::cos(0.314), 0.0, 0.0);
    planes = make_set({chord});
    retake_shape_planes(planes, at(0.015, 0.002, -0.01));
    CHECK((planes.planes[0].normal - chord.normal).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.02, 0.0, -0.01)).norm() < 1e-12);
    planes = make_set({blended});
    retake_shape_planes(planes, at(0.015, 0.005, 0.025));
    const Vector3d side = axes * Vector3d(1, 0, 0);
    CHECK((planes.planes[0].normal - side).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.02, 0.0, 0.025)).norm() < 1e-12);
    // A cap-leaning blend (60° off the side's normal) over a proxy inside: the cap's own plane above it.
    blended.normal = axes * Vector3d(std::cos(1.05), 0.0, std::sin(1.05));
    planes = make_set({blended});
    retake_shape_planes(planes, at(0.015, 0.005, 0.025));
    CHECK((planes.planes[0].normal - axes.col(2)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.015, 0.005, 0.03)).norm() < 1e-12);
    // The same blend under a proxy on the cap: the cap's plane; on the cap with the cap's own plane: as it came.
    planes = make_set({blended});
    retake_shape_planes(planes, at(0.01, -0.004, 0.03));
    CHECK((planes.planes[0].normal - axes.col(2)).norm() < 1e-12);
    const ContactPlane top = cylinder_top_plane(centre, turn);
    planes = make_set({top});
    retake_shape_planes(planes, at(0.01, -0.004, 0.03));
    CHECK(planes.planes[0].normal == top.normal);
    CHECK(planes.planes[0].point_m == top.point_m);
  }
}

TEST_CASE("box planes: a tilted plane under a proxy on its face becomes the face's, under a proxy inside it stays") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(0.01, -0.02, 0.05);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    // The top face's plane blended 20° toward an edge's, through the edge.
    ContactPlane blended = to_contact_plane(box_top_plane(centre, turn, at(0.0, 0.0, 0.06)));
    blended.normal = axes * Vector3d(std::sin(0.35), 0.0, std::cos(0.35));
    blended.point_m = at(0.05, 0.0, 0.05);
    PlaneSet planes = make_set({blended});
    retake_shape_planes(planes, at(0.03, 0.01, 0.05));  // on the top face
    CHECK((planes.planes[0].normal - axes.col(2)).norm() < 1e-12);
    CHECK((planes.planes[0].point_m - at(0.03, 0.01, 0.05)).norm() < 1e-12);
    // Inside, under the blend: it stays, and sinking toward the edge's plane it lets a finger that slid off the edge
    // go (hard case 6).
    planes = make_set({blended});
    retake_shape_planes(planes, at(0.03, 0.01, 0.045));
    CHECK(planes.planes[0].normal == blended.normal);
    CHECK(planes.planes[0].point_m == blended.point_m);
  }
}

TEST_CASE("a finger inside a long cylinder or capsule is held by its plane however far along the axis from the "
          "plane's point") {
  // A cylinder and a capsule of radius 1 cm, 8 cm long, lying along x; the plane is the side's top at x = −3 cm, where
  // the world saw the proxy. The finger is 5 mm into the side at x = +2 cm, 5 cm from the plane's point along it: more
  // than the radius, within the body.
  for (const ShapeKind kind : {ShapeKind::cylinder, ShapeKind::capsule}) {
    Plane wire = test::wire_plane(7, {-0.03, 0.0, 0.01}, {0, 0, 1}, false);
    wire.com_m = {0.0, 0.0, 0.0};
    Eigen::Matrix3d along_x;
    along_x << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // body x, y, z along world y, z, x
    test::set_shape(wire, test::round_shape(kind, 0.01, kind == ShapeKind::cylinder ? 0.08 : 0.06), along_x);
    const ContactPlane plane = to_contact_plane(wire);
    REQUIRE(plane.shaped());
    const ProxySolution solution = project_outside_planes(make_set({plane}), Vector3d(0.02, 0.0, 0.005));
    CHECK(solution.active_count == 1);
    CHECK(solution.proxy_m.z() == Approx(0.01).margin(1e-12));
  }
}

TEST_CASE("a body the straight way from the proxy to the finger passes gets a plane with both in front: the force "
          "ends as the finger leaves it over an edge") {
  for (const Eigen::Quaterniond& turn :
       {Eigen::Quaterniond::Identity(), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()))}) {
    const Eigen::Matrix3d axes = turn.toRotationMatrix();
    const Vector3d centre(0.01, -0.02, 0.05);
    const auto at = [&](double x, double y, double z) { return Vector3d(centre + axes * Vector3d(x, y, z)); };
    const ContactPlane top = to_contact_plane(box_top_plane(centre, turn, at(0.0, 0.0, 0.06)));  // 10 cm cube
    const auto in_front = [](const ContactPlane& plane, const Vector3d& x) {
      return plane.normal.dot(x - plane.point_m) >= -1e-12;
    };

    // The finger inside, pressing the top: the plane about the proxy, as before.
    PlaneSet planes = make_set({top});
    retake_shape_planes(planes, at(0.01, 0.0, 0.05), at(0.01, 0.0, 0.047));
    CHECK(planes.planes[0].normal == top.normal);

    // The proxy has slid past the +x rim, on the edge's plane; the finger has left the cube beside the +x face,
    // behind that plane. The way passes the edge: the +x face's plane under the finger, the proxy in front of it.
    planes = make_set({top});
    retake_shape_planes(planes, at(0.051, 0.0, 0.0505), at(0.0505, 0.0, 0.046));
    CHECK((planes.planes[0].normal - axes.col(0)).norm() < 1e-12);
    CHECK(in_front(planes.planes[0], at(0.051, 0.0, 0.0505)));
    CHECK(in_front(planes.planes[0], at(0.0505, 0.0, 0.046)));
    // Taken about the proxy, as before, the edge's plane would still hold the finger.
    planes = make_set({top});
    retake_shape_planes(planes, at(0.051, 0.0, 0.0505));
    CHECK_FALSE(in_front(planes.planes[0], at(0.0505, 0.0, 0.046)));

    // The proxy over the top inside its rim, the finger beside the +x face: each is behind the other's plane, and
    // the way passes 0.35 mm outside the edge. The edge's plane at its point nearest the way, normal (1, 0, 1)/√2.
    planes = make_set({top});
    retake_shape_planes(planes, at(0.0495, 0.0, 0.051), at(0.051, 0.0, 0.0495));
    CHECK((planes.planes[0].normal - axes * Vector3d(1, 0, 1).normalized()).norm() < 1e-6);
    CHECK((planes.planes[0].point_m - at(0.05, 0.0, 0.05)).norm() < 1e-6);
    CHECK(in_front(planes.planes[0], at(0.0495, 0.0, 0.051)));
    CHECK(in_front(planes.planes[0], at(0.051, 0.0, 0.0495)));

    // A way that cuts the edge (the finger went through the cube's corner region): held about the proxy.
    planes = make_set({top});
    retake_shape_planes(planes, at(0.045, 0.0, 0.05), at(0.051, 0.0, 0.044));
    CHECK(planes.planes[0].normal == top.normal);
  }
}

TEST_CASE("the way past a sphere, a capsule and a cylinder is told from a way through them") {
  // Each body lies along world x through the origin, radius 1 cm (the capsule and the cylinder 6 cm long); the
  // plane came with the proxy above it. A way passing 0.8 mm outside the body leaves the finger free, one dipping
  // 0.1 mm into it keeps the plane about the proxy.
  Plane sphere_wire = test::wire_plane(8, {0.0, 0.0, 0.01}, {0, 0, 1}, false);
  test::set_shape(sphere_wire, test::round_shape(ShapeKind::sphere, 0.01));
  sphere_wire.com_m = {0.0, 0.0, 0.0};
  std::vector<ContactPlane> bodies{to_contact_plane(sphere_wire)};
  for (const ShapeKind kind : {ShapeKind::capsule, ShapeKind::cylinder}) {
    Plane wire = test::wire_plane(7, {0.0, 0.0, 0.01}, {0, 0, 1}, false);
    wire.com_m = {0.0, 0.0, 0.0};
    Eigen::Matrix3d along_x;
    along_x << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // body x, y, z along world y, z, x
    test::set_shape(wire, test::round_shape(kind, 0.01, kind == ShapeKind::cylinder ? 0.06 : 0.04), along_x);
    bodies.push_back(to_contact_plane(wire));
  }
  for (const ContactPlane& body : bodies) {
    INFO("shape " << impetus::to_string(body.shape.kind));
    // Across the body, from 64° up its side to 26° (at x = 0 for the sphere, 1 cm along the others), on the line
    // y + z = 15.3 mm, 10.8 mm from the axis. The finger is behind the plane the proxy had.
    const double x = body.shape.kind == ShapeKind::sphere ? 0.0 : 0.01;
    const Vector3d proxy(x, 0.005, 0.0103), clear_finger(x, 0.0103, 0.005);
    PlaneSet planes = make_set({body});
    retake_shape_planes(planes, proxy, clear_finger);
    CHECK(planes.planes[0].normal.dot(clear_finger - planes.planes[0].point_m) >= 0.0);
    CHECK(planes.planes[0].normal.dot(proxy - planes.planes[0].point_m) >= 0.0);
    // Ends a little nearer (y + z = 14 mm, 9.9 mm from the axis): the way enters, and the finger stays behind.
    const Vector3d through_finger(x, 0.0095, 0.0045);
    planes = make_set({body});
    retake_shape_planes(planes, Vector3d(x, 0.0045, 0.0095), through_finger);
    CHECK(planes.planes[0].normal.dot(through_finger - planes.planes[0].point_m) < 0.0);
  }
}
