// SPDX-License-Identifier: Apache-2.0
// World manager benchmarks: printed, no assertions.
//  1. World::step time for 20 / 200 / 2000 dynamic spheres on the floor (ODE dominates).
//  2. FeatureExtractor::extract time vs number of objects at a constant density around the finger: the query must
//     cost what is near the finger, not the size of the world. index() (once per step, O(N log N)) is shown apart.
//  3. Physics inside the 1 kHz loop (one 1 ms ODE step per haptic tick, as CHAI3D's ODE examples run it) against our
//     20 Hz world (ten 5 ms substeps per 50 ms period): the most spheres each holds within its own period at p99.
// Uses world_manager symbols only.

#include "world_manager/scene.h"
#include "world_manager/features/feature_extractor.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
using impetus::Scene;
using impetus::SceneObject;

struct Percentiles {
  double p50_us;
  double p99_us;
};

Percentiles percentiles(std::vector<double> samples_us) {
  std::sort(samples_us.begin(), samples_us.end());
  const auto at = [&](double fraction) {
    const auto index = static_cast<std::size_t>(fraction * static_cast<double>(samples_us.size() - 1));
    return samples_us[index];
  };
  return {at(0.5), at(0.99)};
}

// `count` spheres of 2 cm radius on a square grid with 5 cm spacing, resting 1 mm above the floor.
Scene sphere_field(int count, double spacing_m) {
  Scene scene;
  scene.source_name = "bench";
  const int side = static_cast<int>(std::ceil(std::sqrt(count)));
  for (int i = 0; i < count; ++i) {
    SceneObject object;
    object.name = "s";
    object.name += std::to_string(i);
    object.shape.kind = impetus::ShapeKind::sphere;
    object.shape.radius_m = 0.02;
    object.dynamic = true;
    object.mass_kg = 0.023;
    object.position_m = {spacing_m * (i % side - side / 2), spacing_m * (i / side - side / 2), 0.021};
    scene.objects.push_back(object);
  }
  return scene;
}

// World::step times over `steps` steps of `scene` at `rate_hz` with `substeps` substeps, a finger resting above.
Percentiles step_percentiles(Scene scene, double rate_hz, int substeps, int steps) {
  scene.physics.world_rate_hz = rate_hz;
  scene.physics.substeps = substeps;
  impetus::World world(scene, impetus::WorldOptions{});
  impetus::HapticReport report{};
  report.haptic_session = 1;
  report.world_session = impetus::WorldOptions{}.world_session;
  report.finger_valid = 1;
  report.finger_m = {0.0, 0.0, 0.05};
  std::vector<double> samples_us;
  for (int i = 0; i < steps; ++i) {
    report.tick = static_cast<std::uint64_t>(i);
    const auto start = Clock::now();
    world.step(&report);
    samples_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  return percentiles(samples_us);
}

void bench_step() {
  std::printf("World::step (20 Hz, 10 substeps), spheres on the floor\n");
  std::printf("%8s %12s %12s\n", "spheres", "p50 [us]", "p99 [us]");
  for (int count : {20, 200, 2000}) {
    const Percentiles p = step_percentiles(sphere_field(count, 0.05), 20.0, 10, count >= 2000 ? 40 : 200);
    std::printf("%8d %12.1f %12.1f\n", count, p.p50_us, p.p99_us);
  }
}

void bench_features() {
  std::printf("\nFeatureExtractor::extract at constant density (one object per 5 cm cell), finger at the centre\n");
  std::printf("%8s %10s %14s %14s %16s\n", "objects", "in reach", "extract p50", "extract p99", "index() p50");
  std::printf("%8s %10s %14s %14s %16s\n", "", "", "[us]", "[us]", "[us]");
  for (int count : {100, 1000, 10000, 100000}) {
    Scene scene = sphere_field(count, 0.05);
    std::vector<impetus::ObjectState> states(scene.objects.size());
    for (std::size_t i = 0; i < states.size(); ++i) {
      const auto& p = scene.objects[i].position_m;
      states[i].pose.position_m = Eigen::Vector3d(p[0], p[1], p[2]);
    }
    impetus::FeatureExtractor extractor(scene);
    std::vector<double> index_us;
    for (int i = 0; i < 5; ++i) {
      const auto start = Clock::now();
      extractor.index(states, 0.05);
      index_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    }
    std::array<impetus::Plane, impetus::kMaxPlanes> planes{};
    impetus::ReachQuery finger;
    finger.position_m = {0.01, 0.01, 0.05};
    finger.velocity_mps = {0.3, 0.0, 0.0};
    std::vector<double> samples_us;
    std::uint32_t in_reach = 0;
    for (int i = 0; i < 2000; ++i) {
      const auto start = Clock::now();
      in_reach = extractor.extract(finger, states, 0.05, planes);
      samples_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    }
    const Percentiles p = percentiles(samples_us);
    std::printf("%8d %10u %14.2f %14.2f %16.1f\n", count, in_reach, p.p50_us, p.p99_us, percentiles(index_us).p50_us);
  }
}

void bench_physics_in_loop() {
  std::printf("\nPhysics in the 1 kHz loop (1 ms step, 1 substep) vs the 20 Hz world (50 ms, 10 substeps), spheres\n");
  std::printf("%8s %22s %22s\n", "spheres", "in-loop step p99 [us]", "20 Hz step p99 [ms]");
  int in_loop_1ms = 0, in_loop_half = 0, slow_world = 0;
  for (int count : {125, 250, 500, 1000, 2000, 4000}) {
    const Scene scene = sphere_field(count, 0.05);
    const double loop_us = step_percentiles(scene, 1000.0, 1, count >= 2000 ? 100 : 300).p99_us;
    const double world_us = step_percentiles(scene, 20.0, 10, count >= 2000 ? 10 : 30).p99_us;
    std::printf("%8d %22.1f %22.2f\n", count, loop_us, world_us / 1e3);
    if (loop_us <= 1000.0) in_loop_1ms = count;
    if (loop_us <= 500.0) in_loop_half = count;
    if (world_us <= 50'000.0) slow_world = count;
  }
  std::printf("most spheres within the period: in the 1 kHz loop %d (1 ms) / %d (0.5 ms, room for the servo); "
              "20 Hz world %d (50 ms): %.1fx / %.1fx (of the sweep's counts)\n",
              in_loop_1ms, in_loop_half, slow_world, in_loop_1ms > 0 ? double(slow_world) / in_loop_1ms : 0.0,
              in_loop_half > 0 ? double(slow_world) / in_loop_half : 0.0);
}

}  // namespace

int main() {
  impetus::init_ode_once();
  bench_step();
  bench_features();
  bench_physics_in_loop();
  return 0;
}
