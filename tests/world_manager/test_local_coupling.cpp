// SPDX-License-Identifier: Apache-2.0
// The world's side of local coupling (world.h, paper §6.3): impulses are applied at the time they were
// rendered (from the report's first moments), so the world's next state is what the haptic side's local model showed;
// the impulse applied is exactly the impulse reported; and the frame carries the response model (contacts, gravity,
// substep).

#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include <algorithm>
#include <random>

using impetus::Coupling;
using impetus::HapticReport;
using impetus::ObjectImpulse;
using impetus::World;
using impetus::WorldOptions;
using impetus::test::make_report;
using impetus::test::make_world;
using Eigen::Vector3d;
using nlohmann::json;

namespace {

json free_cube() {
  return json{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
              {"mass_kg", 2.0}, {"position_m", {0, 0, 0}}};
}

WorldOptions local_options() {
  WorldOptions options;
  options.coupling = Coupling::local;
  options.world_rate_hz = 20.0;
  return options;
}

// Adds impulse J rendered at haptic time t to a running entry (what ImpulseAccumulator does per tick).
void render(ObjectImpulse& entry, const Vector3d& impulse_Ns, double t_s) {
  for (int a = 0; a < 3; ++a) {
    entry.impulse_Ns[a] += impulse_Ns[a];
    entry.impulse_moment_Nss[a] += impulse_Ns[a] * t_s;
  }
}

}  // namespace

TEST_CASE("local coupling: impulses rendered at t_k move a free body by sum J_k (t_end - t_k)/m, as the haptic side "
          "showed, and change its velocity by sum J_k/m") {
  const impetus::Scene scene = impetus::parse_scene(impetus::test::free_body_document(free_cube()), "free.json");
  auto world = make_world(scene, local_options());
  HapticReport report = make_report(9, 50);
  report.haptic_time_s = 0.05;  // first report: the window is the period before it, [0, 0.05]
  report.entry_count = 1;
  ObjectImpulse& entry = report.entries[0];
  entry.object_id = 0;
  entry.epoch = 1;
  // Two pushes at awkward times (not on the 5 ms substep grid) and in different directions.
  render(entry, Vector3d(0.10, 0.02, 0.0), 0.013);
  render(entry, Vector3d(0.04, -0.03, 0.01), 0.041);
  world->step(&report);
  const double m = 2.0;
  const Vector3d expected_x =
      (Vector3d(0.10, 0.02, 0.0) * (0.05 - 0.013) + Vector3d(0.04, -0.03, 0.01) * (0.05 - 0.041)) / m;
  INFO("x " << world->states()[0].pose.position_m.transpose() << " expected " << expected_x.transpose() << " substeps " << scene.physics.substeps);
  CHECK((world->states()[0].pose.position_m - expected_x).norm() < 1e-12);
  CHECK((world->states()[0].velocity_mps - Vector3d(0.14, -0.01, 0.01) / m).norm() < 1e-12);

  // The next window starts at the previous report's time: a push in its very last tick changes the velocity only.
  report.tick = 100;
  report.haptic_time_s = 0.10;
  render(entry, Vector3d(0.02, 0, 0), 0.10);
  const Vector3d x_before = world->states()[0].pose.position_m;
  const Vector3d v_before = world->states()[0].velocity_mps;
  world->step(&report);
  CHECK((world->states()[0].pose.position_m - (x_before + v_before * 0.05)).norm() < 1e-12);
  CHECK(world->states()[0].velocity_mps.x() == Approx(v_before.x() + 0.01).epsilon(1e-12));
}

TEST_CASE("local coupling: the world applies exactly the impulse reported, whatever its timing") {
  const impetus::Scene scene = impetus::parse_scene(impetus::test::free_body_document(free_cube()), "free.json");
  impetus::WorldOptions options = local_options();
  // Random pushes of up to 35 N a tick: more than a device renders, so the world's bound on a report's impulse
  // (World::take_report) is lifted to test the bookkeeping alone.
  options.report_force_limit_N = std::numeric_limits<double>::infinity();
  auto world = make_world(scene, options);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> push(-0.01, 0.02);
  std::uniform_int_distribution<int> ticks(1, 120);  // reports arrive irregularly (real time)
  HapticReport report = make_report(11, 0);
  report.entry_count = 1;
  report.entries[0].object_id = 0;
  report.entries[0].epoch = 1;
  std::uint64_t tick = 0;
  for (int step = 0; step < 60; ++step) {
    const int n = ticks(random);
    for (int k = 0; k < n; ++k) {
      ++tick;
      render(report.entries[0], Vector3d(push(random), push(random), push(random)), tick * 1e-3);
    }
    report.tick = tick;
    report.haptic_time_s = tick * 1e-3;
    world->step(&report);
  }
  const Vector3d reported = impetus::to_eigen(report.entries[0].impulse_Ns);
  CHECK((world->total_impulse_Ns(0) - reported).norm() <= 1e-12 * (1.0 + reported.norm()));
  // And the free body's momentum is that impulse (no gravity, no contacts).
  CHECK((2.0 * world->states()[0].velocity_mps - reported).norm() <= 1e-10);
}

TEST_CASE("local coupling: a cube resting on the floor sends its floor contact, gravity and substep with its plane") {
  const impetus::Scene scene = impetus::load_scene(impetus::test::scene_path("tap.json"));
  auto world = make_world(scene, local_options());
  HapticReport report = make_report(3, 50, {-0.01, 0.0, 0.025}, true);
  report.proxy_m = report.finger_m;
  const impetus::PlaneFrame& frame = world->step(&report);
  CHECK(frame.coupling == Coupling::local);
  CHECK(frame.gravity_mps2[2] == Approx(-9.81));
  CHECK(frame.world_substep_s == Approx(0.05 / scene.physics.substeps));
  const impetus::Plane* cube = nullptr;
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    if (frame.planes[k].object_id == 0) cube = &frame.planes[k];
  }
  REQUIRE(cube != nullptr);
  REQUIRE(cube->local_contact_count == 1);  // the four corner contacts are one support
  CHECK(impetus::to_eigen(cube->local_contacts[0].normal).dot(Vector3d::UnitZ()) > 0.999);  // pushes the cube up
  CHECK(cube->local_contacts[0].friction == Approx(0.06));
  CHECK((cube->local_contacts[0].flags & impetus::kContactHolds) != 0);  // the floor holds any push into it
  CHECK(impetus::test::transport_verdict(frame) == impetus::FrameError::ok);

  // Impulse coupling sends no contacts: the haptic side has no model to feed.
  WorldOptions impulse = local_options();
  impulse.coupling = Coupling::impulse;
  auto other = make_world(scene, impulse);
  const impetus::PlaneFrame& plain = other->step(&report);
  for (std::uint32_t k = 0; k < plain.plane_count; ++k) CHECK(plain.planes[k].local_contact_count == 0);
}

TEST_CASE("local coupling: a body resting on nothing sends what it would land on, the floor or a table under its "
          "whole bounds, gap_m below its lowest point") {
  // A 5 cm box turned 0.3 rad about x falling from 20 cm over the floor; a 3 cm cube falling over a static shelf (a
  // 10 cm box), wholly over its top; another over the shelf's edge; and a ball resting on the shelf (its support faces
  // up, so nothing is added).
  const double turn_rad = 0.3;
  const json box{{"name", "box"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                 {"mass_kg", 0.2}, {"position_m", {0, 0, 0.2}},
                 {"orientation_wxyz", {std::cos(turn_rad / 2), std::sin(turn_rad / 2), 0, 0}},
                 {"dynamic_friction", 0.8}, {"static_friction", 1.0}};
  const json shelf{{"name", "shelf"}, {"shape", "box"}, {"size_m", {0.1, 0.1, 0.1}}, {"dynamic", false},
                   {"position_m", {0.2, 0, 0.05}}, {"dynamic_friction", 0.3}, {"static_friction", 0.3}};
  const json ball{{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.01}, {"dynamic", true}, {"mass_kg", 0.01},
                  {"position_m", {0.23, 0.03, 0.11}}};
  const auto cube = [](const char* name, double x_m) {
    return json{{"name", name}, {"shape", "box"}, {"size_m", {0.03, 0.03, 0.03}}, {"dynamic", true},
                {"mass_kg", 0.05}, {"position_m", {x_m, 0, 0.3}}, {"dynamic_friction", 0.8}, {"static_friction", 1.0}};
  };
  const json document{{"gravity_mps2", {0, 0, -9.81}},
                      {"floor", {{"height_m", 0.0}, {"static_friction", 0.5}, {"dynamic_friction", 0.4}}},
                      {"haptic", {{"reach_radius_m", 0.4}}},
                      {"objects", {box, shelf, ball, cube("over", 0.2), cube("edge", 0.25)}}};
  const impetus::Scene scene = impetus::parse_scene(document, "falling.json");
  auto world = make_world(scene, local_options());
  HapticReport report = make_report(3, 50, {0.1, 0.0, 0.15}, true);
  report.proxy_m = report.finger_m;
  world->step(&report);  // the ball settles onto the shelf
  report.tick = 100;
  const impetus::PlaneFrame& frame = world->step(&report);
  const auto plane_of = [&](std::int32_t id) -> const impetus::Plane* {
    for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
      if (frame.planes[k].object_id == id) return &frame.planes[k];
    }
    return nullptr;
  };
  // The lowest corner of box `id` (half size `half_m`), from the world's pose.
  const auto lowest_m = [&](std::size_t id, double half_m) {
    const impetus::ObjectState& state = world->states()[id];
    double lowest = std::numeric_limits<double>::infinity();
    for (int corner = 0; corner < 8; ++corner) {
      const Vector3d local(corner & 1 ? half_m : -half_m, corner & 2 ? half_m : -half_m, corner & 4 ? half_m : -half_m);
      lowest = std::min(lowest, (state.pose.position_m + state.pose.orientation * local).z());
    }
    return lowest;
  };
  struct Expected {
    std::int32_t id;
    double half_m, surface_m, friction;
  };
  for (const Expected& expected : {Expected{0, 0.025, 0.0, std::sqrt(0.8 * 0.4)},    // the floor
                                   Expected{3, 0.015, 0.1, std::sqrt(0.8 * 0.3)},    // the shelf's top
                                   Expected{4, 0.015, 0.0, std::sqrt(0.8 * 0.4)}}) {  // over its edge: the floor
    CAPTURE(expected.id);
    const impetus::Plane* falling = plane_of(expected.id);
    REQUIRE(falling != nullptr);
    REQUIRE(falling->local_contact_count == 1);
    const impetus::LocalContact& support = falling->local_contacts[0];
    CHECK(impetus::to_eigen(support.normal) == Vector3d::UnitZ());
    CHECK((support.flags & impetus::kContactHolds) != 0);
    CHECK(support.friction == Approx(expected.friction));  // the pair's, as the engine combines it
    const double lowest = lowest_m(static_cast<std::size_t>(expected.id), expected.half_m);
    CHECK(lowest > expected.surface_m + 0.05);
    CHECK(support.gap_m == Approx(lowest - expected.surface_m).epsilon(1e-12));
  }
  CHECK(impetus::test::transport_verdict(frame) == impetus::FrameError::ok);
  // The ball on the shelf has the shelf's support, facing up: nothing is added below it.
  const impetus::Plane* resting = plane_of(2);
  REQUIRE(resting != nullptr);
  REQUIRE(resting->local_contact_count == 1);
  CHECK(resting->local_contacts[0].gap_m == 0.0);
}

TEST_CASE("local coupling: a light ball pushed into the floor in the last tick is held by the floor, not driven in") {
  // A 2.9 g ball resting on the floor; the haptic side pushed it down with 4 mN·s in the very last tick of a window
  // (as a finger touching it just above its equator does). Applied as a bare velocity change after the step it
  // would enter the floor at 1.4 m/s on the next step; applied in the last substep the floor contact takes it.
  const json ball{{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.01}, {"dynamic", true},
                  {"density_kgpm3", 700}, {"position_m", {0, 0, 0.01}}};
  const impetus::Scene scene =
      impetus::parse_scene(json{{"physics", {{"world_rate_hz", 10}, {"substeps", 20}}}, {"objects", {ball}}}, "b.json");
  WorldOptions options = local_options();
  options.world_rate_hz = 10.0;
  auto world = make_world(scene, options);
  HapticReport report = make_report(9, 100);
  report.haptic_time_s = 0.1;
  world->step(&report);  // settles on the floor; the contacts of its last substep are recorded
  report.tick = 200;
  report.haptic_time_s = 0.2;
  report.entry_count = 1;
  ObjectImpulse& entry = report.entries[0];
  entry.object_id = 0;
  entry.epoch = 1;
  render(entry, Vector3d(0, 0, -0.004), 0.2);
  entry.last_tick = 200;
  world->step(&report);
  double lowest_m = world->states()[0].pose.position_m.z();
  CHECK(world->states()[0].velocity_mps.z() > -0.1);  // the floor took the push
  report.tick = 300;
  report.haptic_time_s = 0.3;
  world->step(&report);
  lowest_m = std::min(lowest_m, world->states()[0].pose.position_m.z());
  CHECK(lowest_m > 0.01 - 0.5e-3);  // never more than ODE's contact softness into the floor
  CHECK((world->total_impulse_Ns(0) - Vector3d(0, 0, -0.004)).norm() < 1e-12);  // and the impulse was applied
}
