// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/force_renderer.h"
#include "haptic_controller/god_object.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

TEST_CASE("force is the spring-damper of paper 3.3 with the real elapsed dt") {
  ForceRenderer renderer(100.0);
  const double k = 1000.0, b = 2.0;
  RenderedForce f = renderer.render({0, 0, 0}, {0, 0, -0.001}, k, b, 1e-3);
  REQUIRE((f.force_N - Vector3d(0, 0, 1.0)).norm() < 1e-12);  // first tick: no previous displacement, spring only
  f = renderer.render({0, 0, 0}, {0, 0, -0.003}, k, b, 2e-3);
  // k·0.003 + b·(0.003 − 0.001)/0.002 = 3 + 2
  REQUIRE((f.force_N - Vector3d(0, 0, 5.0)).norm() < 1e-12);
  f = renderer.render({0, 0, 0}, {0, 0, -0.003}, k, b, 0.0);  // no time elapsed: spring only
  REQUIRE((f.force_N - Vector3d(0, 0, 3.0)).norm() < 1e-12);
  REQUIRE(renderer.faults() == 0);
}

TEST_CASE("a contact never pulls: a surface letting go of the finger fast does not drag it along") {
  ForceRenderer renderer(100.0);
  const double k = 2000.0, b = 5.0;
  // 0.5 mm deep, then the surface recedes 0.3 mm in one tick: the damper alone would give 1 − 1.5 = −0.5 N (a pull).
  renderer.render({0, 0, 0}, {0, 0, -0.0005}, k, b, 1e-3);
  RenderedForce f = renderer.render({0, 0, -0.0003}, {0, 0, -0.0005}, k, b, 1e-3);
  REQUIRE(f.force_N.z() == 0.0);
  // Sliding along the surface the damper still brakes sideways, and the push stays: only the pull is removed.
  renderer.render({0, 0, 0}, {0, 0, -0.001}, k, b, 1e-3);
  f = renderer.render({0.0002, 0, 0}, {0, 0, -0.001}, k, b, 1e-3);
  REQUIRE(f.force_N.z() == Approx(2.0));
  REQUIRE(f.force_N.x() == Approx(2000.0 * 0.0002 + 5.0 * 0.2));
  // The finger exactly on the surface: no push direction, no force.
  f = renderer.render({0.01, 0, 0}, {0.01, 0, 0}, k, b, 1e-3);
  REQUIRE(f.force_N == Vector3d::Zero());
}

TEST_CASE("force is clamped to the device maximum, direction kept, and counted") {
  ForceRenderer renderer(10.0);
  const RenderedForce f = renderer.render({0, 0, 0}, {-0.03, 0, -0.04}, 2000.0, 0.0, 1e-3);
  REQUIRE(f.clamped);
  REQUIRE(f.force_N.norm() == Approx(10.0));
  REQUIRE((f.force_N.normalized() - Vector3d(0.6, 0, 0.8)).norm() < 1e-12);
  REQUIRE(renderer.clamps() == 1);
}

TEST_CASE("NaN anywhere gives zero force and a counted fault, and does not poison the next tick") {
  ForceRenderer renderer(10.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  renderer.render({0, 0, 0}, {0, 0, -0.001}, 1000.0, 2.0, 1e-3);
  RenderedForce f = renderer.render({0, 0, 0}, {nan, 0, 0}, 1000.0, 2.0, 1e-3);
  REQUIRE(f.fault);
  REQUIRE(f.force_N == Vector3d::Zero());
  f = renderer.render({0, 0, 0}, {0, 0, -0.001}, nan, 2.0, 1e-3);
  REQUIRE(f.fault);
  REQUIRE(f.force_N == Vector3d::Zero());
  f = renderer.render({0, 0, 0}, {0, 0, -0.001}, 1000.0, 2.0, std::numeric_limits<double>::infinity());
  REQUIRE(f.fault);
  REQUIRE(renderer.faults() == 3);
  f = renderer.render({0, 0, 0}, {0, 0, -0.001}, 1000.0, 2.0, 1e-3);
  REQUIRE(!f.fault);
  REQUIRE((f.force_N - Vector3d(0, 0, 1.0)).norm() < 1e-12);  // spring only: the history was forgotten
}

namespace {

// A 0.1 kg point finger pushed against a static wall x ≥ 0 by a constant 1 N hand force at 1 kHz. The wall force is
// held over each tick (zero-order hold, as on the device), and the finger is integrated exactly under that constant
// force (x += v·T + ½a·T², v += a·T), so the finger's energy changes by exactly the work the wall did: any rise is the
// controller's, not the integrator's. A passive wall (non-negative storage, empty at the start) can never have done
// net positive work on the finger, so the finger's energy — kinetic + potential of the hand force — can never exceed
// its starting value. Returns the largest rise above the start over 10 s, relative to the start.
double worst_energy_rise(double stiffness_Npm, double damping_Nspm) {
  constexpr double mass_kg = 0.1, dt_s = 1e-3, push_N = 1.0;
  const PlaneSet wall = make_set({make_plane({0, 0, 0}, {1, 0, 0})});
  GodObject god;
  ForceRenderer renderer(1e9);  // no clamp: the wall itself must be passive
  double x = 0.01, v = -0.5;  // approaching at 0.5 m/s
  auto energy = [&](double pos, double vel) { return 0.5 * mass_kg * vel * vel + push_N * pos; };
  const double start = energy(x, v);
  double worst = 0.0;
  for (int tick = 0; tick < 10000; ++tick) {
    const Vector3d finger(x, 0, 0);
    const GodObjectResult& contact = god.solve(wall, finger, dt_s);
    const RenderedForce f = renderer.render(contact.contact.proxy_m, finger, stiffness_Npm, damping_Nspm, dt_s);
    const double wall_N = contact.contact.active_count > 0 ? f.force_N.x() : 0.0;
    const double a = (wall_N - push_N) / mass_kg;
    x += v * dt_s + 0.5 * a * dt_s * dt_s;
    v += a * dt_s;
    worst = std::max(worst, (energy(x, v) - start) / std::abs(start));
  }
  return worst;
}

}  // namespace

TEST_CASE("a static wall at 2 kN/m with the default damping never gains energy over 10 s (passivity)") {
  REQUIRE(worst_energy_rise(2000.0, passivity_damping_Nspm(2000.0, 1e-3)) <= 1e-9);  // rounding only
}

TEST_CASE("a static wall at 20 kN/m with the default damping never gains energy over 10 s (passivity)") {
  REQUIRE(worst_energy_rise(20000.0, passivity_damping_Nspm(20000.0, 1e-3)) <= 1e-9);  // rounding only
}

TEST_CASE("the passivity check can fail: an undamped 20 kN/m sampled wall gains energy") {
  REQUIRE(worst_energy_rise(20000.0, 0.0) > 0.01);
}
