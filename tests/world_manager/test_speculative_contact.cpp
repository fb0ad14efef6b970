// SPDX-License-Identifier: Apache-2.0
// Speculative contacts (engine/speculative_contact.h, scene physics.speculative_contacts): a pair that meets within a
// substep closes its gap and no more, so an impact neither sinks into the other body nor bounces off the penetration
// correction. Each world test runs with them off too, where the fault they remove must show.
#include "world_manager/engine/speculative_contact.h"

#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <span>

namespace impetus {
namespace {

// The 5 ms substep of the default 20 Hz × 10 world, as one substep per world step so every substep is observed.
nlohmann::json substep_physics(bool speculative) {
  return {{"world_rate_hz", 200}, {"substeps", 1}, {"auto_disable", false}, {"speculative_contacts", speculative}};
}

void step(World& world) { world.step(std::span<const HapticReport* const>{}); }

struct Drop {
  double deepest_m = 0.0;         // the ball's deepest point below the floor's surface, over the run
  double impact_speed_mps = 0.0;  // its fastest fall
  double rebound_speed_mps = 0.0; // its fastest rise after the first impact
};

// A 2 cm wooden ball dropped from 13 cm above the floor (1.6 m/s at the floor: 8 mm per 5 ms substep), for 0.4 s.
Drop drop_ball(double restitution, bool speculative) {
  const nlohmann::json document{
      {"physics", substep_physics(speculative)},
      {"floor", {{"restitution", restitution}}},
      {"objects",
       {{{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.02}, {"dynamic", true}, {"mass_kg", 0.023},
         {"position_m", {0.0, 0.0, 0.15}}, {"restitution", restitution}}}}};
  auto world = test::make_world(parse_scene(document, "drop.json"));
  Drop drop;
  bool fell = false;
  for (int i = 0; i < 80; ++i) {
    step(*world);
    const ObjectState& ball = world->states()[0];
    drop.deepest_m = std::max(drop.deepest_m, 0.02 - ball.pose.position_m.z());
    const double vz = ball.velocity_mps.z();
    if (!fell) drop.impact_speed_mps = std::max(drop.impact_speed_mps, -vz);
    if (vz > 0.0) fell = true;
    if (fell) drop.rebound_speed_mps = std::max(drop.rebound_speed_mps, vz);
  }
  return drop;
}

}  // namespace

TEST_CASE("speculative contacts: a dropped ball meets the floor without sinking in and bounces as its restitution "
          "says") {
  const double restitution = GENERATE(0.0, 0.5);
  const Drop with = drop_ball(restitution, true);
  const Drop without = drop_ball(restitution, false);
  INFO("restitution " << restitution << ": deepest " << with.deepest_m * 1e3 << " mm (off: " << without.deepest_m * 1e3
                      << " mm); impact " << with.impact_speed_mps << " m/s, rebound " << with.rebound_speed_mps
                      << " m/s (off: " << without.rebound_speed_mps << " m/s)");
  REQUIRE(with.impact_speed_mps > 1.5);
  // Without them the ball ends its impact substep up to v·h = 8 mm deep; with them only the contact's softness
  // (m·g/k: microns) is left.
  CHECK(without.deepest_m > 1e-3);
  CHECK(with.deepest_m < 0.02e-3);
  if (restitution == 0.0) {
    // No bounce: the floor does not hand back what the correction of a penetration would (ERP·depth/h).
    CHECK(with.rebound_speed_mps < 0.01);
    CHECK(without.rebound_speed_mps > 0.05);
  } else {
    // The rebound is e times the impact speed, less the one substep of gravity it spends at the surface (g·h).
    CHECK(with.rebound_speed_mps == Approx(restitution * with.impact_speed_mps).margin(9.81 * 0.005 + 1e-3));
  }
}

TEST_CASE("speculative contacts: a cube sliding into another passes on its momentum without a kick") {
  // Free space: a 1 kg cube at 0.5 m/s and a 0.5 kg one 11.25 mm ahead (the impact falls mid-substep, where the
  // penetration, and so the correction's kick, is largest). Restitution 0: they go on together at m1·v/(m1 + m2).
  auto run = [](bool speculative) {
    nlohmann::json document = test::free_body_document(
        {{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true}, {"mass_kg", 1.0},
         {"position_m", {0.0, 0.0, 0.0}}, {"linear_velocity_mps", {0.5, 0.0, 0.0}}});
    document["objects"].push_back({{"name", "cube2"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}},
                                   {"dynamic", true}, {"mass_kg", 0.5}, {"position_m", {0.06125, 0.0, 0.0}}});
    document["physics"] = substep_physics(speculative);
    auto world = test::make_world(parse_scene(document, "two_cubes.json"));
    double deepest_m = 0.0;
    for (int i = 0; i < 100; ++i) {
      step(*world);
      deepest_m = std::max(deepest_m, 0.05 - (world->states()[1].pose.position_m.x() -
                                              world->states()[0].pose.position_m.x()));
    }
    const double parting_mps = world->states()[1].velocity_mps.x() - world->states()[0].velocity_mps.x();
    const double momentum_Ns = world->states()[0].velocity_mps.x() + 0.5 * world->states()[1].velocity_mps.x();
    return std::tuple{deepest_m, parting_mps, momentum_Ns, world->states()[1].velocity_mps.x()};
  };
  const auto [deepest_m, parting_mps, momentum_Ns, second_mps] = run(true);
  const auto [off_deepest_m, off_parting_mps, off_momentum_Ns, off_second_mps] = run(false);
  INFO("with: deepest " << deepest_m * 1e3 << " mm, parting at " << parting_mps << " m/s; off: deepest "
                        << off_deepest_m * 1e3 << " mm, parting at " << off_parting_mps << " m/s");
  CHECK(momentum_Ns == Approx(0.5).epsilon(1e-9));
  CHECK(off_momentum_Ns == Approx(0.5).epsilon(1e-9));
  CHECK(deepest_m < 0.02e-3);
  CHECK(std::abs(parting_mps) < 1e-3);
  CHECK(second_mps == Approx(0.5 / 1.5).epsilon(0.01));
  // Off: the cubes end the impact substep 1.25 mm into each other and the correction parts them.
  CHECK(off_deepest_m > 1e-3);
  CHECK(off_parting_mps > 0.01);
}

TEST_CASE("speculative contacts: a fast ball wakes the sleeping box it is about to hit and meets it as a body") {
  // The box sleeps after 0.5 s at rest; the ball rolls at 2 m/s (1 cm per substep) and arrives at about 0.75 s. It
  // must wake the box one substep early, so that the two meet without overlapping: a sleeping box is fixed geometry
  // until woken, with no speculative contacts of its own.
  nlohmann::json physics = substep_physics(true);
  physics["auto_disable"] = true;
  const nlohmann::json document{
      {"physics", physics},
      {"objects",
       {{{"name", "box"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true}, {"mass_kg", 0.5},
         {"position_m", {0.0, 0.0, 0.025}}},
        {{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.02}, {"dynamic", true}, {"mass_kg", 0.2},
         {"position_m", {-1.5453, 0.0, 0.02}}, {"linear_velocity_mps", {2.0, 0.0, 0.0}},
         {"angular_velocity_radps", {0.0, 100.0, 0.0}}}}}};
  auto world = test::make_world(parse_scene(document, "wake.json"));
  for (int i = 0; i < 130; ++i) step(*world);  // 0.65 s
  REQUIRE(world->asleep(0));
  REQUIRE(world->states()[1].pose.position_m.x() < -0.1);
  double deepest_m = 0.0;
  for (int i = 0; i < 200; ++i) {
    step(*world);
    deepest_m = std::max(deepest_m, (world->states()[1].pose.position_m.x() + 0.02) -
                                        (world->states()[0].pose.position_m.x() - 0.025));
  }
  INFO("box at x = " << world->states()[0].pose.position_m.x() << " m, ball at "
                     << world->states()[1].pose.position_m.x() << " m; deepest overlap " << deepest_m * 1e3 << " mm");
  CHECK(world->states()[0].pose.position_m.x() > 0.01);  // struck at ~0.6 m/s, braked at mu·g: ~3 cm
  // Woken on contact instead, the ball ends its arrival substep up to v·h = 10 mm inside. What is left is the
  // contact's give under the impact (~60 N for one substep) and the box's tilt, which this centre-line measure
  // counts as overlap: below 0.1 mm.
  CHECK(deepest_m < 0.1e-3);
}

TEST_CASE("speculative_contacts: the gap a sphere closes on a plane, and the body put back exactly") {
  prepare_engines();
  dWorldID world = dWorldCreate();
  dGeomID plane = dCreatePlane(nullptr, 0.0, 0.0, 1.0, 0.0);
  dGeomID sphere = dCreateSphere(nullptr, 0.02);
  dBodyID body = dBodyCreate(world);
  dGeomSetBody(sphere, body);
  dBodySetPosition(body, 0.1, 0.2, 0.021234);  // 1.234 mm above the plane
  const dReal before[3] = {dBodyGetPosition(body)[0], dBodyGetPosition(body)[1], dBodyGetPosition(body)[2]};
  dContact out[4];

  // Reaches: one contact, 1.234 mm apart, midway across the gap below the centre.
  REQUIRE(speculative_contacts(sphere, body, plane, {0.0, 0.0, -0.003}, out, 4) == 1);
  CHECK(out[0].geom.depth == Approx(-0.001234).margin(1e-12));
  CHECK(out[0].geom.normal[2] == Approx(1.0));
  CHECK(out[0].geom.pos[0] == Approx(0.1));
  CHECK(out[0].geom.pos[2] == Approx(0.000617).margin(1e-12));
  CHECK(std::memcmp(before, dBodyGetPosition(body), sizeof before) == 0);
  // Falls short, or moves along the plane: nothing.
  CHECK(speculative_contacts(sphere, body, plane, {0.0, 0.0, -0.001}, out, 4) == 0);
  CHECK(speculative_contacts(sphere, body, plane, {0.01, 0.0, 0.0}, out, 4) == 0);
  // Already in: the overlap, positive.
  dBodySetPosition(body, 0.1, 0.2, 0.019);
  REQUIRE(speculative_contacts(sphere, body, plane, {0.0, 0.0, -0.001}, out, 4) == 1);
  CHECK(out[0].geom.depth == Approx(0.001).margin(1e-12));

  dGeomDestroy(sphere);
  dGeomDestroy(plane);
  dWorldDestroy(world);
}

}  // namespace impetus
