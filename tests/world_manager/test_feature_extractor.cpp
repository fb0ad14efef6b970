#include "world_manager/features/feature_extractor.h"
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <set>

using impetus::FeatureExtractor;
using impetus::ReachQuery;
using impetus::ObjectState;
using impetus::ReachCandidate;
using impetus::Scene;
using impetus::SceneObject;
using impetus::ShapeKind;
using Eigen::Vector3d;

namespace {

constexpr double kPeriod_s = 0.05;

// 500 random objects of every shape, static and dynamic, scattered in a 1 m cube, with random poses and speeds.
struct RandomWorld {
  Scene scene;
  std::vector<ObjectState> states;
};

RandomWorld make_random_world(std::uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  RandomWorld world;
  world.scene.haptic.reach_radius_m = 0.05;
  world.scene.floor.height_m = 0.0;
  for (int i = 0; i < count; ++i) {
    SceneObject object;
    object.name = "o";
    object.name += std::to_string(i);
    object.shape.kind = static_cast<ShapeKind>(i % 4);
    object.shape.box_size_m = {0.01 + 0.08 * unit(rng), 0.01 + 0.08 * unit(rng), 0.01 + 0.08 * unit(rng)};
    object.shape.radius_m = 0.005 + 0.04 * unit(rng);
    object.shape.length_m = 0.01 + 0.1 * unit(rng);
    object.dynamic = i % 3 != 0;
    object.mass_kg = object.dynamic ? 0.1 : 0.0;
    world.scene.objects.push_back(object);
    ObjectState state;
    state.pose.position_m = Vector3d(unit(rng), unit(rng), unit(rng));
    state.pose.orientation = Eigen::Quaterniond::UnitRandom();
    if (object.dynamic) state.velocity_mps = Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    world.states.push_back(state);
  }
  return world;
}

// Brute force: every object (and the floor), exact distance against the reach of DESIGN.md §1 step 4.
std::set<std::int32_t> brute_force_within_reach(const RandomWorld& world, const ReachQuery& finger) {
  std::set<std::int32_t> ids;
  const double finger_speed = finger.velocity_mps.norm();
  for (std::size_t i = 0; i < world.states.size(); ++i) {
    const auto surface = impetus::nearest_surface_point(world.scene.objects[i].shape, world.states[i].pose,
                                                        finger.position_m);
    const double reach_m =
        world.scene.haptic.reach_radius_m + (finger_speed + world.states[i].velocity_mps.norm()) * kPeriod_s;
    if (surface.signed_distance_m <= reach_m) ids.insert(static_cast<std::int32_t>(i));
  }
  if (finger.position_m.z() <= world.scene.haptic.reach_radius_m + finger_speed * kPeriod_s) {
    ids.insert(world.scene.floor_object_id());
  }
  return ids;
}

}  // namespace

TEST_CASE("the feature query returns exactly the objects within reach, checked against brute force") {
  const RandomWorld world = make_random_world(2024, 500);
  FeatureExtractor extractor(world.scene);
  extractor.index(world.states, kPeriod_s);
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t total_found = 0;
  std::size_t total_tested = 0;
  for (int trial = 0; trial < 300; ++trial) {
    ReachQuery finger;
    finger.position_m = Vector3d(unit(rng), unit(rng), 0.1 * unit(rng) + (trial % 2) * unit(rng));
    finger.velocity_mps = (trial % 5 == 0 ? 2.0 : 0.3) * Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    std::vector<ReachCandidate> found;
    extractor.within_reach(finger, world.states, kPeriod_s, found);
    std::set<std::int32_t> found_ids;
    for (const ReachCandidate& c : found) found_ids.insert(c.object_id);
    CHECK(found_ids.size() == found.size());  // each once
    CHECK(found_ids == brute_force_within_reach(world, finger));
    CHECK(std::is_sorted(found.begin(), found.end(), [](const ReachCandidate& a, const ReachCandidate& b) {
      return a.surface.signed_distance_m < b.surface.signed_distance_m;
    }));
    total_found += found.size();
    total_tested += extractor.last_candidate_count();
  }
  // The grid looks at a neighbourhood, not the world: on average far fewer than all 500 objects are tested exactly.
  INFO("found " << total_found << ", tested " << total_tested);
  CHECK(total_tested < 300 * 500 / 5);
  CHECK(total_found > 300);  // the trials do hit objects, so the comparison means something
}

TEST_CASE("more objects within reach than a frame holds: the nearest kMaxPlanes are kept") {
  // 200 small spheres packed around the finger, all within reach.
  RandomWorld world;
  world.scene.haptic.reach_radius_m = 0.2;
  world.scene.floor.present = false;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-0.1, 0.1);
  for (int i = 0; i < 200; ++i) {
    SceneObject object;
    object.name = "s";
    object.name += std::to_string(i);
    object.shape.kind = ShapeKind::sphere;
    object.shape.radius_m = 0.005;
    world.scene.objects.push_back(object);
    ObjectState state;
    state.pose.position_m = Vector3d(unit(rng), unit(rng), unit(rng));
    world.states.push_back(state);
  }
  FeatureExtractor extractor(world.scene);
  extractor.index(world.states, kPeriod_s);
  ReachQuery finger;
  std::array<impetus::Plane, impetus::kMaxPlanes> planes{};
  const std::uint32_t count = extractor.extract(finger, world.states, kPeriod_s, planes);
  REQUIRE(count == impetus::kMaxPlanes);
  std::vector<double> distances;
  for (const auto& state : world.states) distances.push_back(state.pose.position_m.norm() - 0.005);
  std::sort(distances.begin(), distances.end());
  const double farthest_kept_m = distances[impetus::kMaxPlanes - 1];
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto& centre = world.states[static_cast<std::size_t>(planes[i].object_id)].pose.position_m;
    CHECK(centre.norm() - 0.005 <= farthest_kept_m + 1e-15);
  }
}

TEST_CASE("planes carry the object's state, friction and the floor") {
  const Scene scene = impetus::load_scene(impetus::test::scene_path("tap.json"));
  auto world = impetus::test::make_world(scene);
  impetus::HapticReport report = impetus::test::make_report(1, 50, {0.0, 0.01, 0.03}, true);
  const impetus::PlaneFrame& frame = world->step(&report);
  REQUIRE(frame.plane_count == 2);
  const impetus::Plane& cube = frame.planes[0].object_id == 0 ? frame.planes[0] : frame.planes[1];
  const impetus::Plane& floor = frame.planes[0].object_id == 0 ? frame.planes[1] : frame.planes[0];
  CHECK(cube.flags == impetus::kPlaneDynamic);
  CHECK(cube.normal[0] == Approx(-1.0));
  CHECK(cube.point_m[0] == Approx(0.005).margin(1e-4));  // the −x face (the cube has barely settled)
  CHECK(cube.inverse_mass_per_kg == Approx(1.0));
  CHECK(cube.static_friction == 0.08);
  CHECK(cube.dynamic_friction == 0.06);
  CHECK(floor.object_id == scene.floor_object_id());
  CHECK(floor.flags == 0u);
  CHECK(floor.normal[2] == 1.0);
  CHECK(floor.point_m[2] == 0.0);
  CHECK(frame.stiffness_Npm == 2000.0);
}
