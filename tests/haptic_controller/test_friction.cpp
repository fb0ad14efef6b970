// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/god_object.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

namespace {

constexpr double kDt_s = 1e-3;

// |f_t| / |f_n| of the spring force k(D − C) on a floor whose normal is +z.
double force_ratio(const Vector3d& proxy, const Vector3d& finger) {
  const Vector3d d = proxy - finger;
  return std::hypot(d.x(), d.y()) / d.z();
}

}  // namespace

TEST_CASE("friction: the proxy sticks inside the static cone, then slides back onto the dynamic cone") {
  constexpr double mu_static = 0.5, mu_dynamic = 0.3, depth_m = 0.01, step_m = 1e-5;
  const PlaneSet floor = make_set({make_plane({0, 0, 0}, {0, 0, 1}, 0, false, mu_static, mu_dynamic)});
  GodObject god;
  double max_sticking_ratio = 0.0;
  int first_slip = -1;
  for (int tick = 0; tick < 1000 && first_slip < 0; ++tick) {
    const Vector3d finger(tick * step_m, 0.0, -depth_m);
    const GodObjectResult& r = god.solve(floor, finger, kDt_s);
    const double ratio = force_ratio(r.contact.proxy_m, finger);
    REQUIRE(ratio <= mu_static + 1e-9);  // never outside the static cone
    REQUIRE(std::abs(r.contact.proxy_m.z()) < 1e-12);
    if (r.sticking) {
      REQUIRE(std::abs(r.contact.proxy_m.x()) < 1e-12);  // stuck where it landed
      max_sticking_ratio = ratio;
    } else {
      first_slip = tick;
      REQUIRE(ratio == Approx(mu_dynamic).epsilon(1e-9));  // slid back onto the dynamic cone
      REQUIRE(r.contact.proxy_m.x() < finger.x());           // still trailing the finger
    }
  }
  REQUIRE(first_slip > 0);
  // It held until the tangential force reached μ_s·|f_n| (to within one step of finger motion).
  REQUIRE(max_sticking_ratio > mu_static - step_m / depth_m - 1e-12);
  REQUIRE(first_slip == static_cast<int>(std::floor(mu_static * depth_m / step_m + 1e-9)) + 1);
}

TEST_CASE("friction: a frictionless plane never holds the proxy") {
  const PlaneSet floor = make_set({make_plane({0, 0, 0}, {0, 0, 1})});
  GodObject god;
  for (int tick = 0; tick < 10; ++tick) {
    const Vector3d finger(tick * 1e-3, 0.0, -0.01);
    god.solve(floor, finger, kDt_s);
    REQUIRE((god.result().contact.proxy_m - Vector3d(finger.x(), 0.0, 0.0)).norm() < 1e-12);
  }
}

TEST_CASE("friction: a moving surface carries the proxy with it until the static cone is left") {
  constexpr double speed_mps = 0.1, depth_m = 0.01, mu_static = 0.605, mu_dynamic = 0.4;
  ContactPlane belt = make_plane({0, 0, 0}, {0, 0, 1}, 3, true, mu_static, mu_dynamic);
  belt.velocity_mps = Vector3d(speed_mps, 0.0, 0.0);  // a conveyor: the surface moves, the plane stays
  const PlaneSet planes = make_set({belt});
  GodObject god;
  const Vector3d finger(0.0, 0.0, -depth_m);
  god.solve(planes, finger, kDt_s);  // lands at the origin
  for (int tick = 1; tick <= 50; ++tick) god.solve(planes, finger, kDt_s);
  REQUIRE(god.result().sticking);
  REQUIRE(god.result().contact.proxy_m.x() == Approx(50 * speed_mps * kDt_s).epsilon(1e-9));
  // Carried until |f_t| would exceed μ_s·|f_n| = 6.05 mm of stretch, i.e. for 60 ticks; then it slips.
  bool slipped = false;
  for (int tick = 51; tick <= 70 && !slipped; ++tick) {
    god.solve(planes, finger, kDt_s);
    slipped = !god.result().sticking;
    if (slipped) {
      REQUIRE(tick == 61);
      REQUIRE(force_ratio(god.result().contact.proxy_m, finger) == Approx(mu_dynamic).epsilon(1e-9));
    }
  }
  REQUIRE(slipped);
}

TEST_CASE("friction: a rotating object carries the anchor with v + ω × (p − com)") {
  ContactPlane top = make_plane({0, 0, 0}, {0, 0, 1}, 4, true, 1.0, 1.0);
  top.com_m = Vector3d(0.0, 0.0, -0.025);
  top.angular_velocity_radps = Vector3d(0.0, 0.0, 2.0);  // spinning about the vertical through the com
  const PlaneSet planes = make_set({top});
  GodObject god;
  const Vector3d finger(0.01, 0.0, -0.01);
  god.solve(planes, finger, kDt_s);
  god.solve(planes, finger, kDt_s);
  // ω × (p − com) = 2ẑ × (0.01, 0, 0.025) = (0, 0.02, 0) m/s → 20 µm in one tick.
  REQUIRE(god.result().contact.proxy_m.y() == Approx(2e-5).epsilon(1e-9));
}
