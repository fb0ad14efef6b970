// SPDX-License-Identifier: Apache-2.0
// The closed loop (loop/simulation.h) against the scripted trial: steered to a trajectory's own points it must give
// that trajectory's trial bit for bit; its arguments are checked before any tick.

#include "loop/in_process_trial.h"
#include "loop/simulation.h"
#include "spidar_sim/trajectory.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace impetus {
namespace {

std::string tap_scene() { return std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json"; }

TEST_CASE("a closed loop steered along the tap trajectory ends the trial where the scripted tap does, to the bit") {
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    INFO(to_string(coupling));
    InProcessTrialOptions scripted;
    scripted.scene_path = tap_scene();
    scripted.trajectory = "tap";
    scripted.coupling = coupling;
    const nlohmann::json expected = run_in_process_trial(scripted);

    const Trajectory tap = load_trajectory("tap");
    SimulationOptions options;
    options.trial.scene_path = tap_scene();
    options.trial.coupling = coupling;
    options.fingers = {{"finger", tap.position_at(0.0)}};
    Simulation loop(options);
    // The scripted trial's last tick finds its device gone; every tick before it had the finger.
    const std::uint64_t ticks = expected["haptic"]["ticks"].get<std::uint64_t>() - 1;
    std::vector<FingerTick> records(1);
    double peak_force_N = 0.0;
    for (std::uint64_t t = 0; t < ticks; ++t) {
      const Vec3 target_m = tap.position_at(loop.device_time_s() + loop.tick_period_s());
      REQUIRE(loop.step(1, std::span<const Vec3>(&target_m, 1), records) == 1);
      const Vec3& f = records[0].force_N;
      peak_force_N = std::max(peak_force_N, std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    }
    const nlohmann::json summary = loop.finish();
    CHECK(summary["objects"]["cube"]["position"] == expected["objects"]["cube"]["position"]);
    CHECK(summary["objects"]["cube"]["impulse_Ns"] == expected["objects"]["cube"]["impulse_Ns"]);
    CHECK(peak_force_N == expected["haptic"]["max_force_N"].get<double>());
    CHECK(loop.objects()[0].position_m[0] == expected["objects"]["cube"]["position"][0].get<double>());
  }
}

TEST_CASE("a closed loop refuses a trajectory, a bad finger, a target that is not finite and steps after it ended") {
  SimulationOptions options;
  options.trial.scene_path = tap_scene();
  options.fingers = {{"finger", {-0.03, 0.0, 0.025}}};
  SECTION("options") {
    SimulationOptions scripted = options;
    scripted.trial.trajectory = "tap";
    CHECK_THROWS_WITH(Simulation(scripted), Catch::Contains("no trajectory"));
    SimulationOptions none = options;
    none.fingers.clear();
    CHECK_THROWS_WITH(Simulation(none), Catch::Contains("1 to"));
    SimulationOptions twice = options;
    twice.fingers.push_back(options.fingers[0]);
    CHECK_THROWS_WITH(Simulation(twice), Catch::Contains("given twice"));
    SimulationOptions outside = options;
    outside.fingers[0].start_m = {3.0, 0.0, 0.0};
    CHECK_THROWS_WITH(Simulation(outside), Catch::Contains("outside the device's frame"));
  }
  SECTION("steps") {
    Simulation loop(options);
    const Vec3 nan_target{0.0, std::numeric_limits<double>::quiet_NaN(), 0.0};
    CHECK_THROWS_WITH(loop.set_target(0, nan_target), Catch::Contains("target_m"));
    CHECK_THROWS_WITH(loop.set_target(1, {0.0, 0.0, 0.0}), Catch::Contains("finger: 1"));
    CHECK_THROWS_WITH(loop.step(1, std::span<const Vec3>(&nan_target, 1), {}), Catch::Contains("tick 0, finger 0"));
    std::vector<FingerTick> too_few(1);
    CHECK_THROWS_WITH(loop.step(2, {}, too_few), Catch::Contains("room for 2"));
    CHECK(loop.ticks() == 0);  // nothing was ticked by a refused call
    CHECK(loop.step(10, {}, {}) == 10);
    loop.finish();
    CHECK_THROWS_AS(loop.step(1, {}, {}), std::logic_error);
  }
}

}  // namespace
}  // namespace impetus
