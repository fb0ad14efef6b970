// SPDX-License-Identifier: Apache-2.0
// World manager benchmarks: printed, no assertions.
//  1. World::step time for 20 / 200 / 2000 dynamic spheres on the floor, on every engine (the engine dominates).
//  2. FeatureExtractor::extract time vs number of objects at a constant density around the finger: the query must
//     cost what is near the finger, not the size of the world. index() (once per step, O(N log N)) is shown apart.
//  3. Physics inside the 1 kHz loop (one 1 ms ODE step per haptic tick, as CHAI3D's ODE examples run it) against our
//     20 Hz world (ten 5 ms substeps per 50 ms period): the most spheres each holds within its own period at p99.
//  4. "Model only what a scene needs": a world of N resting spheres, 10 rolling ones and one a finger presses, with
//     sleeping on (physics.auto_disable) and off: World::step once the resting ones sleep. The step should cost
//     what moves, not what exists. On every engine.
// Uses world_manager symbols only.
//
// --quick: section 4 only up to 10 k objects (scripts/bench.sh --short).

#include "world_manager/scene.h"
#include "world_manager/features/feature_extractor.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <string_view>
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
// Sleeping off: sections 1-3 measure what simulating every body costs (section 4 measures sleeping).
Scene sphere_field(int count, double spacing_m) {
  Scene scene;
  scene.source_name = "bench";
  scene.physics.auto_disable = false;
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
  std::printf("%8s %8s %12s %12s %16s\n", "engine", "spheres", "p50 [us]", "p99 [us]", "p50 per body [us]");
  for (const impetus::EngineEntry& entry : impetus::engine_entries()) {
    for (int count : {20, 200, 2000}) {
      Scene scene = sphere_field(count, 0.05);
      scene.physics.engine = std::string(entry.name);
      const Percentiles p = step_percentiles(scene, 20.0, 10, count >= 2000 ? 40 : 200);
      std::printf("%8s %8d %12.1f %12.1f %16.2f\n", std::string(entry.name).c_str(), count, p.p50_us, p.p99_us,
                  p.p50_us / count);
    }
  }
}

void bench_features() {
  std::printf("\nFeatureExtractor::extract at constant density (one object per 5 cm cell), finger at the centre\n");
  std::printf("%8s %10s %14s %14s %16s %18s\n", "objects", "in reach", "extract p50", "extract p99", "index() p50",
              "reindex(10) p50");
  std::printf("%8s %10s %14s %14s %16s %18s\n", "", "", "[us]", "[us]", "[us]", "[us]");
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
    // What a world step re-indexes: the 10 objects that moved (each by 1 cm, so some change cells).
    std::vector<std::size_t> moved;
    for (std::size_t k = 0; k < 10; ++k) moved.push_back(k * states.size() / 10);
    std::vector<double> reindex_us;
    for (int i = 0; i < 20; ++i) {
      for (const std::size_t id : moved) states[id].pose.position_m.x() += (i % 2 == 0 ? 0.01 : -0.01);
      const auto start = Clock::now();
      extractor.reindex(states, 0.05, moved);
      reindex_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
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
    std::printf("%8d %10u %14.2f %14.2f %16.1f %18.2f\n", count, in_reach, p.p50_us, p.p99_us,
                percentiles(index_us).p50_us, percentiles(reindex_us).p50_us);
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

// N spheres of 2 cm radius resting on the floor 5 cm apart (y >= 0), and 10 more rolling along +x at 0.2 m/s in a lane
// of their own at y = -0.5 m, 20 cm apart, so they never meet the resting ones within the run.
Scene resting_field_with_rollers(int resting, bool sleeping) {
  Scene scene;
  scene.source_name = "bench";
  scene.physics.auto_disable = sleeping;
  const int side = static_cast<int>(std::ceil(std::sqrt(resting)));
  constexpr double kRadius_m = 0.02;
  constexpr double kSpacing_m = 0.05;
  const auto sphere = [&](double x, double y, double vx) {
    SceneObject object;
    object.name = "s";
    object.name += std::to_string(scene.objects.size());
    object.shape.kind = impetus::ShapeKind::sphere;
    object.shape.radius_m = kRadius_m;
    object.dynamic = true;
    object.mass_kg = 0.023;
    object.position_m = {x, y, kRadius_m};
    object.linear_velocity_mps = {vx, 0.0, 0.0};
    object.angular_velocity_radps = {0.0, vx / kRadius_m, 0.0};  // rolling without slipping: ω × r = v
    scene.objects.push_back(object);
  };
  for (int i = 0; i < resting; ++i) sphere(kSpacing_m * (i % side), kSpacing_m * (i / side), 0.0);
  for (int i = 0; i < 10; ++i) sphere(0.2 * i, -0.5, 0.2);
  return scene;
}

struct SleepingRun {
  Percentiles step;
  double build_s;
  double settle_s;
  std::size_t awake;
};

// Builds the world, lets it settle for 1 s (resting bodies fall asleep after 0.5 s), then times `steps` steps with a
// finger pressing sphere 0 down into the floor (a growing running total: a new impulse every step).
SleepingRun run_sleeping(std::string_view engine, int resting, bool sleeping, int steps) {
  Scene scene = resting_field_with_rollers(resting, sleeping);
  scene.physics.engine = std::string(engine);
  auto start = Clock::now();
  impetus::World world(scene, impetus::WorldOptions{});
  const double build_s = std::chrono::duration<double>(Clock::now() - start).count();
  impetus::HapticReport report{};
  report.haptic_session = 1;
  report.world_session = impetus::WorldOptions{}.world_session;
  report.finger_valid = 1;
  report.finger_m = {0.0, 0.0, 0.035};
  report.proxy_m = {0.0, 0.0, 0.04};
  report.entry_count = 1;
  report.entries[0].object_id = 0;
  const int settle_steps = static_cast<int>(std::ceil(1.0 * scene.physics.world_rate_hz));
  std::uint64_t tick = 0;
  const auto press = [&] {
    tick += 50;
    report.tick = tick;
    report.haptic_time_s = 1e-3 * static_cast<double>(tick);
    // 0.5 N down for the 50 ms of a world period.
    report.entries[0].impulse_Ns[2] -= 0.025;
    report.entries[0].last_tick = tick;
    world.step(&report);
  };
  start = Clock::now();
  for (int i = 0; i < settle_steps; ++i) press();
  const double settle_s = std::chrono::duration<double>(Clock::now() - start).count();
  std::vector<double> samples_us;
  for (int i = 0; i < steps; ++i) {
    start = Clock::now();
    press();
    samples_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  std::size_t awake = 0;
  for (std::size_t id = 0; id < scene.objects.size(); ++id) {
    if (world.states()[id].velocity_mps.norm() > 0.0) ++awake;
  }
  return {percentiles(samples_us), build_s, settle_s, awake};
}

void bench_sleeping(bool quick) {
  std::printf("\nModel only what a scene needs: N resting spheres + 10 rolling + 1 pressed, World::step (20 Hz, 10 "
              "substeps) after 1 s of settling\n");
  std::printf("%8s %8s %9s %12s %12s %10s %10s %8s\n", "engine", "resting", "sleeping", "p50 [us]", "p99 [us]",
              "build [s]", "settle [s]", "moving");
  std::vector<int> counts{1000, 10000};
  if (!quick) counts.push_back(100000);
  for (const impetus::EngineEntry& entry : impetus::engine_entries()) {
    const std::string engine(entry.name);
    for (const int count : counts) {
      for (const bool sleeping : {false, true}) {
        if (!sleeping && count > 10000) {
          // Every body simulated: ODE's hash space clears an n×n bit matrix of tested pairs at every collide (1.25 GB
          // per substep here), and any engine then pays for 100 k bodies in every substep.
          std::printf("%8s %8d %9s %12s (not run: every body simulated, seconds per step)\n", engine.c_str(), count,
                      "off", "-");
          continue;
        }
        const int steps = !sleeping && count >= 10000 ? 10 : 100;
        const SleepingRun run = run_sleeping(entry.name, count, sleeping, steps);
        std::printf("%8s %8d %9s %12.1f %12.1f %10.2f %10.2f %8zu\n", engine.c_str(), count, sleeping ? "on" : "off",
                    run.step.p50_us, run.step.p99_us, run.build_s, run.settle_s, run.awake);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  impetus::prepare_engines();
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  if (argc > 1 && std::string(argv[1]) == "--sleeping") {
    bench_sleeping(false);
    return 0;
  }
  bench_step();
  bench_features();
  bench_physics_in_loop();
  bench_sleeping(quick);
  return 0;
}
