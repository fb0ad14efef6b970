// SPDX-License-Identifier: Apache-2.0
// Every registered engine against physics it must get right, so a comparison of engines compares their models and
// not their mistakes: Coulomb sliding, resting contact forces, sleeping, and bitwise repeatable runs.
#include "world_manager/deform/deformable_surface.h"
#include "world_manager/engine/engine_registry.h"
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

// An engine of `scene` (its physics.engine), its bodies left 1.5 s without forces to come to rest (and fall asleep).
std::unique_ptr<RigidBodyEngine> rested_engine(const Scene& scene) {
  prepare_engines();
  auto engine = make_engine(scene);
  NoForces none;
  for (int step = 0; step < 30; ++step) engine->step(10, 0.005, false, none);
  return engine;
}

// A 1 kg, 5 cm cube on a floor, both with dynamic friction `mu` (so the pair's is `mu`: scene.h combine_friction).
json sliding_cube(double mu, double speed_mps) {
  return json{{"floor", {{"static_friction", mu}, {"dynamic_friction", mu}}},
              {"objects",
               {{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                 {"mass_kg", 1.0}, {"position_m", {0.0, 0.0, 0.025}}, {"static_friction", mu},
                 {"dynamic_friction", mu}, {"linear_velocity_mps", {speed_mps, 0.0, 0.0}}}}}};
}

TEST_CASE("on every engine a cube, a box or a mesh, sliding on the floor stops after v²/(2·μ·g), on its face") {
  constexpr double kMu = 0.06;
  constexpr double kSpeed_mps = 0.5;
  const double expected_m = kSpeed_mps * kSpeed_mps / (2.0 * kMu * 9.81);
  for (const EngineEntry& entry : engine_entries()) {
    for (const bool mesh : {false, true}) {
      INFO(entry.name << (mesh ? ", a mesh cube" : ", a box"));
      json document = sliding_cube(kMu, kSpeed_mps);
      if (mesh) {
        json& cube = document["objects"][0];
        cube.erase("size_m");
        cube["shape"] = "mesh";
        cube["file"] = std::string(IMPETUS_SOURCE_DIR) + "/scenes/meshes/cube.obj";  // 5 cm, as the box
      }
      const Scene scene = engine_scene(document, entry.name);
      auto world = test::make_world(scene);
      for (int step = 0; step < 40; ++step) world->step(nullptr);  // 2 s: the slide takes 0.85 s
      const ObjectState& cube = world->states()[0];
      // The friction force is μ·m·g on either engine's solver once it has converged; what is left is the substep's
      // discretisation of the stop, v·h ≈ 2.5 mm of 212 mm: 2 %.
      CHECK(cube.pose.position_m.x() == Approx(expected_m).epsilon(0.02));
      CHECK(cube.velocity_mps.norm() < 1e-3);
      // On its face: a margin around a mesh's triangles would hold it up by that much.
      CHECK(std::abs(cube.pose.position_m.z() - 0.025) < 1e-4);
    }
  }
}

// A 2 × 4 × 8 cm box as an OBJ file, its edges turned from the file's axes by `turn`: a closed mesh whose principal
// axes are not the file's.
std::string turned_box_obj(const Eigen::Matrix3d& turn) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "impetus_turned_box.obj";
  std::ofstream out(path);
  const Eigen::Vector3d half(0.01, 0.02, 0.04);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1 ? 1 : -1) * half.x(), (k & 2 ? 1 : -1) * half.y(), (k & 4 ? 1 : -1) * half.z());
    const Eigen::Vector3d v = turn * corner;
    out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  }
  // Outward-wound faces (vertex k at bit 0: +x, bit 1: +y, bit 2: +z; OBJ counts from 1).
  const int faces[12][3] = {{1, 3, 7}, {1, 7, 5}, {2, 6, 8}, {2, 8, 4}, {1, 5, 6}, {1, 6, 2},
                            {3, 4, 8}, {3, 8, 7}, {1, 2, 4}, {1, 4, 3}, {5, 7, 8}, {5, 8, 6}};
  for (const auto& f : faces) out << "f " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
  return path.string();
}

TEST_CASE("on every engine a spinning mesh whose principal axes are not its file's keeps its angular momentum") {
  // The box's inertia about the file's axes has large products of inertia: an engine that takes a diagonal inertia
  // (Bullet) must turn its body frame to the principal axes and back, or the momentum wanders by tens of per cent.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const std::string file = turned_box_obj(turn);
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const json document = {{"gravity_mps2", {0.0, 0.0, 0.0}},
                           {"floor", nullptr},
                           {"objects",
                            {{{"name", "box"}, {"shape", "mesh"}, {"file", file}, {"dynamic", true},
                              {"mass_kg", 0.1}, {"position_m", {0.0, 0.0, 0.5}},
                              {"angular_velocity_radps", {3.0, 1.0, 2.0}}}}}};
    const Scene scene = engine_scene(document, entry.name);
    const Eigen::Matrix3d inertia_body = inertia_kgm2(scene.objects[0].shape, scene.objects[0].mass_kg);
    REQUIRE((inertia_body - Eigen::Matrix3d(inertia_body.diagonal().asDiagonal())).cwiseAbs().maxCoeff() >
            0.05 * inertia_body.trace());
    auto world = test::make_world(scene);
    const auto momentum = [&](const ObjectState& state) {
      const Eigen::Matrix3d body = state.pose.orientation.toRotationMatrix();
      return Eigen::Vector3d(body * inertia_body * body.transpose() * state.angular_velocity_radps);
    };
    const Eigen::Vector3d start = momentum(world->states()[0]);
    for (int step = 0; step < 40; ++step) world->step(nullptr);  // 2 s, about a turn
    // Torque-free: the world-frame angular momentum stays, to the integrators' own drift (both engines step the
    // rotation explicitly: a few tenths of a per cent here).
    CHECK((momentum(world->states()[0]) - start).norm() < 0.02 * start.norm());
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

TEST_CASE("every engine's block is read by its engine and checked whichever engine runs") {
  json document = sliding_cube(0.1, 0.0);
  document["physics"] = {{"engine", "bullet"},
                         {"bullet", {{"solver_iterations", 30}, {"solver", "direct"}}},
                         {"ode", {{"solver", "direct"}}}};
  const Scene scene = parse_scene(document, "b.json");
  CHECK(scene.physics.bullet.solver_iterations == 30);
  CHECK(scene.physics.bullet.solver == BulletParams::Solver::direct);
  CHECK(scene.physics.ode.solver == OdeParams::Solver::direct);
  // A mistake in the block of the engine not chosen is still an error, so it shows before a run chooses that engine.
  document["physics"] = {{"engine", "bullet"}, {"ode", {{"solver", "dantzig"}}}};
  CHECK_THROWS_WITH(parse_scene(document, "b.json"), Catch::Contains("/physics/ode/solver") &&
                                                         Catch::Contains("\"quickstep\" or \"direct\""));
  document["physics"] = {{"bullet", {{"solver", "pgs"}}}};
  CHECK_THROWS_WITH(parse_scene(document, "b.json"), Catch::Contains("/physics/bullet/solver") &&
                                                         Catch::Contains("\"sequential_impulse\" or \"direct\""));
  document["physics"] = {{"engine", "havok"}};
  CHECK_THROWS_WITH(parse_scene(document, "b.json"), Catch::Contains("ode or bullet"));
}

// Five 4 cm boxes, 1 kg and 1 g in turn: every touching pair 1000:1, the classic case an iterative solver cannot carry.
json mass_ratio_stack() {
  json document{{"objects", json::array()}};
  for (int k = 0; k < 5; ++k) {
    document["objects"].push_back({{"name", "box" + std::to_string(k)}, {"shape", "box"}, {"size_m", {0.04, 0.04, 0.04}},
                                   {"dynamic", true}, {"mass_kg", k % 2 == 0 ? 1.0 : 0.001},
                                   {"position_m", {0.0, 0.0, 0.02 + 0.04 * k}}});
  }
  return document;
}

TEST_CASE("on every engine the direct solver holds a 1000:1 stack that the iterative one drops") {
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const auto largest_displacement_m = [&](const char* solver) {
      json document = mass_ratio_stack();
      document["physics"] = {{"ode", {{"solver", solver == std::string("iterative") ? "quickstep" : solver}}},
                             {"bullet", {{"solver", solver == std::string("iterative") ? "sequential_impulse" : solver}}}};
      const Scene scene = engine_scene(document, entry.name);
      auto world = test::make_world(scene);
      for (int step = 0; step < 40; ++step) world->step(nullptr);  // 2 s
      double largest_m = 0.0;
      for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Vec3& start = scene.objects[id].position_m;
        const Eigen::Vector3d start_m(start[0], start[1], start[2]);
        largest_m = std::max(largest_m, (world->states()[id].pose.position_m - start_m).norm());
      }
      return largest_m;
    };
    // Held: the five contacts' springs under the stack's weight sink it by a few tenths of a millimetre at most
    // (3 kg on the default 4·10⁶ N/m spring per point is micrometres; the rest is the first substeps' settling).
    CHECK(largest_displacement_m("direct") < 1e-3);
    // Dropped: a light box under a heavy one slides out, by centimetres.
    CHECK(largest_displacement_m("iterative") > 1e-2);
  }
}

TEST_CASE("on every engine a push wakes the body it pushes and what touches it, not resting bodies nearby") {
  // Three 2 cm balls on the floor: a and b touching, c 1 cm from b (within Bullet's 2 cm broadphase margin, so a
  // grouping by bounding boxes would join it). All three fall asleep; a push on a wakes a and b, and c sleeps on.
  json document{{"objects", json::array()}};
  for (const double x : {0.0, 0.04, 0.09}) {
    document["objects"].push_back({{"name", "ball" + std::to_string(document["objects"].size())}, {"shape", "sphere"},
                                   {"radius_m", 0.02}, {"dynamic", true}, {"mass_kg", 0.03},
                                   {"position_m", {x, 0.0, 0.02}}});
  }
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const Scene scene = engine_scene(document, entry.name);
    auto engine = rested_engine(scene);
    NoForces none;
    for (std::size_t id = 0; id < 3; ++id) CHECK(engine->asleep(id));
    // Towards b, for one substep: 0.3 mN·s on 30 g, 1 cm/s.
    engine->add_force(0, Eigen::Vector3d(0.06, 0.0, 0.0), Eigen::Vector3d::Zero());
    engine->step(10, 0.005, false, none);
    CHECK_FALSE(engine->asleep(0));
    CHECK_FALSE(engine->asleep(1));
    CHECK(engine->asleep(2));
  }
}

TEST_CASE("on every engine bodies rest in the dent of a plastic slab, roll into it, and stay up beside it") {
  // A 10 × 10 × 2 cm slab on the floor (top face at z = 2 cm), three 3 mm balls of 10 g on it: one over where a dent
  // will be (x = −2 cm), one where the slope of another will be (4 mm from its centre at x = +2 cm), one 3 cm away.
  constexpr double kTop_m = 0.02;
  constexpr double kRadius_m = 0.003;
  const auto ball = [=](const std::string& name, double x_m, double y_m) {
    return json{{"name", name}, {"shape", "sphere"}, {"radius_m", kRadius_m}, {"dynamic", true}, {"mass_kg", 0.01},
                {"position_m", {x_m, y_m, kTop_m + kRadius_m}}};
  };
  json objects = json::array();
  objects.push_back({{"name", "slab"}, {"shape", "box"}, {"size_m", {0.1, 0.1, 0.02}}, {"dynamic", false},
                     {"position_m", {0.0, 0.0, 0.01}}});
  objects.push_back(ball("over", -0.02, 0.0));
  objects.push_back(ball("slope", 0.024, 0.0));
  objects.push_back(ball("beside", 0.0, 0.03));
  const json document{{"objects", objects}};
  for (const EngineEntry& entry : engine_entries()) {
    INFO(entry.name);
    const Scene scene = engine_scene(document, entry.name);
    auto engine = rested_engine(scene);
    NoForces none;
    CHECK(engine->asleep(1));
    // Dents 3.5 mm deep (a push of 0.2 N·s beyond yield each, straight down at x = ∓2 cm).
    const DeformableMaterial clay;
    DeformableSurface surface(clay, Eigen::Vector3d(0.05, 0.05, 0.01), Eigen::Vector3d(0.0, 0.0, 0.01),
                              Eigen::Quaterniond::Identity());
    for (const double x_m : {-0.02, 0.02}) {
      surface.press({0.2, Eigen::Vector3d(x_m, 0.0, kTop_m), Eigen::Vector3d(x_m, 0.0, kTop_m)});
    }
    surface.yield_period();
    const double dent_m = 0.01 - surface.height_m(-0.02, 0.0);
    REQUIRE(dent_m > 0.003);
    engine->dent_top(0, surface.dented_top());
    CHECK_FALSE(engine->asleep(1));  // woken: the surface went from under it
    for (int step = 0; step < 40; ++step) engine->step(10, 0.005, false, none);  // 2 s
    ObjectState over, slope, beside;
    engine->read_state(1, over);
    engine->read_state(2, slope);
    engine->read_state(3, beside);
    // The dent's crest curves less than the ball (2·d/a² = 0.2 per mm against 1/r = 0.33), so the ball sits at its
    // bottom: lower by the dent's depth, to the heightfield's 1 mm facets (a chord's sag under a 3 mm ball).
    CHECK(over.pose.position_m.z() == Approx(kTop_m - dent_m + kRadius_m).margin(2e-4));
    CHECK(std::abs(over.pose.position_m.x() + 0.02) < 1e-3);
    CHECK(std::abs(over.pose.position_m.y()) < 1e-3);
    // The ball on the other's slope rolled down and rests at its bottom.
    CHECK(std::abs(slope.pose.position_m.x() - 0.02) < 1e-3);
    CHECK(slope.pose.position_m.z() == Approx(kTop_m - dent_m + kRadius_m).margin(2e-4));
    // Beside the dents the slab is as it was.
    CHECK(beside.pose.position_m.z() == Approx(kTop_m + kRadius_m).margin(1e-4));
    CHECK((beside.pose.position_m.head<2>() - Eigen::Vector2d(0.0, 0.03)).norm() < 1e-4);
  }
}

}  // namespace
}  // namespace impetus
