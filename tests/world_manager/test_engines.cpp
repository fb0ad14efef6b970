// SPDX-License-Identifier: Apache-2.0
// Every registered engine against physics it must get right, so a comparison of engines compares their models and
// not their mistakes: Coulomb sliding, resting contact forces, sleeping, and bitwise repeatable runs.
#include "world_manager/engine/engine_registry.h"
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace impetus {
namespace {

using nlohmann::json;

struct NoForces final : SubstepHook {
  void before_substep(int) override {}
};

Scene engine_scene(json document, std::string_view engine) {
  document["physics"]["engine"] = std::string(engine);
  return parse_scene(document, "engines.json");
}

// A 1 kg, 5 cm cube on a floor, both with dynamic friction `mu` (so the pair's is `mu`: scene.h combine_friction).
json sliding_cube(double mu, double speed_mps) {
  return json{{"floor", {{"static_friction", mu}, {"dynamic_friction", mu}}},
              {"objects",
               {{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                 {"mass_kg", 1.0}, {"position_m", {0.0, 0.0, 0.025}}, {"static_friction", mu},
                 {"dynamic_friction", mu}, {"linear_velocity_mps", {speed_mps, 0.0, 0.0}}}}}};
}

TEST_CASE("on every engine a cube sliding on the floor stops after v²/(2·μ·g)") {
  constexpr double kMu = 0.06;
  constexpr double kSpeed_mps = 0.5;
  const double expected_m = kSpeed_mps * kSpeed_mps / (2.0 * kMu * 9.81);
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const Scene scene = engine_scene(sliding_cube(kMu, kSpeed_mps), entry.name);
    auto world = test::make_world(scene);
    for (int step = 0; step < 40; ++step) world->step(nullptr);  // 2 s: the slide takes 0.85 s
    const ObjectState& cube = world->states()[0];
    // The friction force is μ·m·g on either engine's solver once it has converged; what is left is the substep's
    // discretisation of the stop, v·h ≈ 2.5 mm of 212 mm: 2 %.
    CHECK(cube.pose.position_m.x() == Approx(expected_m).epsilon(0.02));
    CHECK(cube.velocity_mps.norm() < 1e-3);
    CHECK(std::abs(cube.pose.position_m.z() - 0.025) < 1e-4);
  }
}

TEST_CASE("on every engine a resting cube's contacts carry its weight, it falls asleep, and a push wakes it") {
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const Scene scene = engine_scene(sliding_cube(0.5, 0.0), entry.name);
    prepare_engines();
    auto engine = make_engine(scene);
    NoForces none;
    for (int step = 0; step < 30; ++step) engine->step(10, 0.005, true, none);  // 1.5 s at rest
    // μ·N summed over the cube's floor contacts: μ·m·g when the contacts carry its weight.
    CHECK(engine->contacts().friction_capacity_N(0) == Approx(0.5 * 9.81).epsilon(0.01));
    CHECK(engine->contacts().holds(0, Eigen::Vector3d(0, 0, -1)));
    CHECK(engine->asleep(0));
    CHECK(engine->moved().empty());
    // Held for one 5 ms substep: 1 N·s, against friction that takes 0.25 N·s over the other nine.
    engine->add_force(0, Eigen::Vector3d(200.0, 0.0, 0.0), Eigen::Vector3d::Zero());
    engine->step(10, 0.005, false, none);
    CHECK_FALSE(engine->asleep(0));
    REQUIRE(engine->moved().size() == 1);
    Eigen::Vector3d velocity_mps, angular_radps;
    engine->velocity(0, velocity_mps, angular_radps);
    CHECK(velocity_mps.x() > 0.5);
  }
}

TEST_CASE("on every engine two worlds of one scene stay bitwise equal, stepped apart or interleaved") {
  json document{{"objects", json::array()}};
  for (int k = 0; k < 6; ++k) {
    const double x = 0.06 * k;
    document["objects"].push_back({{"name", "box" + std::to_string(k)}, {"shape", "box"}, {"size_m", {0.04, 0.04, 0.04}},
                                   {"dynamic", true}, {"mass_kg", 0.3}, {"position_m", {x, 0.0, 0.05 + 0.03 * k}},
                                   {"angular_velocity_radps", {1.0, 2.0, 0.5 * k}}});
    document["objects"].push_back({{"name", "ball" + std::to_string(k)}, {"shape", "sphere"}, {"radius_m", 0.02},
                                   {"dynamic", true}, {"mass_kg", 0.2}, {"position_m", {x + 0.01, 0.005, 0.2}},
                                   {"linear_velocity_mps", {0.0, 0.1 * k, -0.5}}});
  }
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const Scene scene = engine_scene(document, entry.name);
    auto alone = test::make_world(scene);
    for (int step = 0; step < 40; ++step) alone->step(nullptr);
    auto first = test::make_world(scene);
    auto second = test::make_world(scene);
    for (int step = 0; step < 40; ++step) {
      first->step(nullptr);
      second->step(nullptr);
    }
    const std::vector<double> expected = test::state_bits(*alone);
    CHECK(test::state_bits(*first) == expected);
    CHECK(test::state_bits(*second) == expected);
    // And the pile did something: every body fell.
    for (const ObjectState& state : alone->states()) CHECK(state.pose.position_m.z() < 0.2);
  }
}

TEST_CASE("an engine's own block is accepted only for that engine") {
  json document = sliding_cube(0.1, 0.0);
  document["physics"] = {{"engine", "bullet"}, {"bullet", {{"solver_iterations", 30}}}};
  CHECK(parse_scene(document, "b.json").physics.bullet.solver_iterations == 30);
  document["physics"] = {{"engine", "bullet"}, {"ode", {{"solver_iterations", 30}}}};
  CHECK_THROWS_WITH(parse_scene(document, "b.json"), Catch::Contains("/physics") && Catch::Contains("ode"));
  document["physics"] = {{"engine", "havok"}};
  CHECK_THROWS_WITH(parse_scene(document, "b.json"), Catch::Contains("ode or bullet"));
}

}  // namespace
}  // namespace impetus
