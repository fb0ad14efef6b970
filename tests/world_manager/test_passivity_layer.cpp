// SPDX-License-Identifier: Apache-2.0
// The impulse port's books and the passivity layer (world_manager/couplings/passivity_layer.h), on a free body where
// every number has a closed form. Pushes stay below what the device's 10 N could give in a 20 Hz period (0.5 N·s), so
// the world's report limit leaves them whole.
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <cmath>

using impetus::Coupling;
using impetus::HapticReport;
using impetus::PortEnergy;
using impetus::WorldOptions;
using impetus::test::add_entry;
using impetus::test::make_report;
using impetus::test::make_world;
using Eigen::Vector3d;
using nlohmann::json;

namespace {

constexpr double kMass_kg = 0.2;

// A 0.2 kg sphere, free in space (no gravity, no floor), moving at `velocity_mps`.
impetus::Scene free_sphere(const Vector3d& velocity_mps = Vector3d::Zero()) {
  const json sphere{{"name", "ball"},         {"shape", "sphere"},
                    {"radius_m", 0.05},       {"dynamic", true},
                    {"mass_kg", kMass_kg},    {"position_m", {0, 0, 0}},
                    {"linear_velocity_mps", {velocity_mps.x(), velocity_mps.y(), velocity_mps.z()}}};
  return impetus::parse_scene(impetus::test::free_body_document(sphere), "free.json");
}

WorldOptions options(Coupling coupling, bool passivity) {
  WorldOptions o;
  o.coupling = coupling;
  o.passivity = passivity;
  return o;
}

// One report pushing the ball with `impulse_Ns`, the hand having put in `hand_input_J` behind it.
HapticReport push(const Vector3d& impulse_Ns, double hand_input_J) {
  HapticReport report = make_report(42, 50);
  add_entry(report, 0, 1, impetus::to_vec3(impulse_Ns));
  report.entries[0].hand_input_J = hand_input_J;
  return report;
}

double kinetic_J(const impetus::World& world) { return 0.5 * kMass_kg * world.states()[0].velocity_mps.squaredNorm(); }

}  // namespace

TEST_CASE("the port's books hold the kinetic energy a push gives and the hand's input, with the layer off") {
  auto world = make_world(free_sphere(), options(Coupling::impulse, false));
  const HapticReport report = push({0.3, -0.1, 0.0}, 0.01);
  world->step(&report);
  const PortEnergy& books = world->port().energy(0);
  CHECK(books.hand_input_J == 0.01);
  CHECK(books.port_work_J == Approx(kinetic_J(*world)).epsilon(1e-12));  // J·(v₀+v₁)/2 from rest: ½m·v₁²
  CHECK(books.overdraft_J() == Approx(kinetic_J(*world) - 0.01).epsilon(1e-12));
  CHECK(books.withheld_J == 0.0);
  CHECK(books.damped_J == 0.0);
  CHECK(books.interventions == 0);
  CHECK(world->states()[0].velocity_mps.isApprox(Vector3d(1.5, -0.5, 0.0), 1e-12));
}

TEST_CASE("the layer gives a body no more kinetic energy than the hand put in") {
  const Vector3d impulse_Ns(0.3, -0.1, 0.0);
  const double full_J = impulse_Ns.squaredNorm() / (2.0 * kMass_kg);

  SECTION("no input: nothing of the push goes in, all of it is counted") {
    auto world = make_world(free_sphere(), options(Coupling::impulse, true));
    const HapticReport report = push(impulse_Ns, 0.0);
    world->step(&report);
    const PortEnergy& books = world->port().energy(0);
    CHECK(world->states()[0].velocity_mps.norm() <= 1e-15);
    CHECK(books.withheld_J == Approx(full_J).epsilon(1e-12));
    CHECK(books.removed_impulse_Ns == Approx(impulse_Ns.norm()).epsilon(1e-12));
    CHECK(books.port_work_J <= books.hand_input_J);
    // What the coupling took from the report is still the whole of it: the layer's share is counted apart.
    CHECK(world->total_impulse_Ns(0).isApprox(impulse_Ns, 1e-15));
  }
  SECTION("a quarter of the energy: half the push (ΔKE grows with its square from rest)") {
    auto world = make_world(free_sphere(), options(Coupling::impulse, true));
    const HapticReport report = push(impulse_Ns, 0.25 * full_J);
    world->step(&report);
    const PortEnergy& books = world->port().energy(0);
    CHECK(world->states()[0].velocity_mps.isApprox(0.5 * impulse_Ns / kMass_kg, 1e-12));
    CHECK(kinetic_J(*world) == Approx(0.25 * full_J).epsilon(1e-12));
    CHECK(books.withheld_J == Approx(0.75 * full_J).epsilon(1e-12));
    CHECK(books.removed_impulse_Ns == Approx(0.5 * impulse_Ns.norm()).epsilon(1e-12));
  }
  SECTION("enough input: the push goes in whole, as with the layer off") {
    auto world = make_world(free_sphere(), options(Coupling::impulse, true));
    const HapticReport report = push(impulse_Ns, 2.0 * full_J);
    world->step(&report);
    CHECK(world->states()[0].velocity_mps.isApprox(impulse_Ns / kMass_kg, 1e-12));
    CHECK(world->port().energy(0).interventions == 0);
  }
}

TEST_CASE("the layer lets a push brake a body, and reverse it no faster than it came without input") {
  // Moving at 0.5 m/s, pushed back by 0.3 N·s: whole, it would leave at 1 m/s (0.1 J from 0.025 J). With no input the
  // most it may leave with is the 0.025 J it brought: it leaves at 0.5 m/s, an elastic bounce.
  auto world = make_world(free_sphere({0.5, 0.0, 0.0}), options(Coupling::impulse, true));
  const HapticReport report = push({-0.3, 0.0, 0.0}, 0.0);
  world->step(&report);
  CHECK(world->states()[0].velocity_mps.isApprox(Vector3d(-0.5, 0.0, 0.0), 1e-12));
  const PortEnergy& books = world->port().energy(0);
  CHECK(books.withheld_J == Approx(0.075).epsilon(1e-12));
  CHECK(books.port_work_J == Approx(0.0).margin(1e-15));

  // A push that only brakes (to rest) goes in whole: it takes energy out.
  auto braked = make_world(free_sphere({0.5, 0.0, 0.0}), options(Coupling::impulse, true));
  const HapticReport brake = push({-0.1, 0.0, 0.0}, 0.0);
  braked->step(&brake);
  CHECK(braked->states()[0].velocity_mps.norm() <= 1e-15);
  CHECK(braked->port().energy(0).interventions == 0);
  CHECK(braked->port().energy(0).port_work_J == Approx(-0.025).epsilon(1e-12));
}

TEST_CASE("a penalty force from a finger inside a body gives it no energy the hand did not put in") {
  // Position coupling: the finger sampled 1 cm inside the ball pushes it for the whole period; no hand input came.
  for (const bool passivity : {false, true}) {
    CAPTURE(passivity);
    auto world = make_world(free_sphere(), options(Coupling::position, passivity));
    HapticReport report = make_report(42, 50, {0.04, 0.0, 0.0}, true);
    report.proxy_m = {0.04, 0.0, 0.0};
    world->step(&report);
    const PortEnergy& books = world->port().energy(0);
    if (passivity) {
      CHECK(kinetic_J(*world) <= 1e-12);
      // A force held over a substep is admitted by the kinetic energy it gives the free body, h²|F|²/2m from rest:
      // with no input none of it goes in, and nothing is left for the damper.
      CHECK(books.withheld_J > 0.0);
      CHECK(books.damped_J == 0.0);
      CHECK(books.port_work_J <= books.hand_input_J + 1e-15);
      CHECK(books.unrecovered_J == 0.0);
    } else {
      // The books are kept exactly off too: the penalty's work is the ball's kinetic energy.
      CHECK(kinetic_J(*world) > 0.0);
      CHECK(books.port_work_J == Approx(kinetic_J(*world)).epsilon(1e-9));
    }
  }
}

TEST_CASE("the layer hands back what a body left unspent through a whole step, and cannot spend it after") {
  // 0.1 J of input behind a 0.1 N·s push that gives the ball 0.025 J: 0.075 J left over. It has sat in the budget
  // only since this step, so it stays; after the next step (a small push, no new input) it goes back to the hand in
  // the frame, and a third push with no input finds nothing to spend.
  for (const bool passivity : {false, true}) {
    CAPTURE(passivity);
    auto world = make_world(free_sphere(), options(Coupling::impulse, passivity));
    HapticReport report = push({0.1, 0.0, 0.0}, 0.1);
    const impetus::PlaneFrame& first = world->step(&report);
    CHECK(first.port_layer == (passivity ? 1u : 0u));
    CHECK(first.port_returned_J == 0.0);
    report.tick += 50;
    report.haptic_time_s += 0.05;
    report.entries[0].impulse_Ns[0] += 1e-4;
    const impetus::PlaneFrame& second = world->step(&report);
    const PortEnergy& books = world->port().energy(0);
    if (!passivity) {
      CHECK(second.port_returned_J == 0.0);
      CHECK(books.returned_J == 0.0);
      continue;
    }
    // Left over after the second push: 0.1 − ½m·v² with v = 0.1001/0.2 m/s.
    const double left_J = 0.1 - 0.5 * kMass_kg * std::pow(0.1001 / kMass_kg, 2);
    CHECK(books.returned_J == Approx(left_J).epsilon(1e-9));
    CHECK(second.port_returned_J == Approx(left_J).epsilon(1e-9));
    CHECK(books.overdraft_J() == Approx(0.0).margin(1e-15));
    report.tick += 50;
    report.haptic_time_s += 0.05;
    report.entries[0].impulse_Ns[0] += 0.05;
    const double before_J = kinetic_J(*world);
    world->step(&report);
    CHECK(kinetic_J(*world) == Approx(before_J).epsilon(1e-12));  // withheld whole: the budget went back
    CHECK(world->port().energy(0).withheld_J > 0.0);
  }
}
