// SPDX-License-Identifier: Apache-2.0
// The in-process loop against the three daemons: the same nodes over the in-process links must reproduce a trial
// run through shared memory bit for bit (docs/architecture.md §6: the same trial in one process or three gives the same
// outcome).

#include "tests/integration/trial_support.h"
#include "tests/integration/users_support.h"
#include "loop/in_process_trial.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

namespace impetus {
namespace {

void check_same_trial(const std::string& name, Coupling coupling, std::uint64_t phase_ticks) {
  const std::string coupling_name = to_string(coupling);
  const test::Trial processes =
      test::run_trial(name + "-processes", "--scene scenes/tap.json --trajectory tap --clock lockstep --coupling " +
                                               coupling_name + " --phase " + std::to_string(phase_ticks));
  REQUIRE(processes.exit_status == 0);

  InProcessTrialOptions options;
  options.scene_path = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  options.trajectory = "tap";
  options.coupling = coupling;
  options.phase_ticks = phase_ticks;
  options.out_dir = test::out_dir(name + "-in-process");
  const nlohmann::json summary = run_in_process_trial(options);

  for (const char* log : {"world.csv", "haptic.csv", "device.csv"}) {
    INFO(log);
    const std::string in_process = test::read_text(options.out_dir / log);
    CHECK(in_process.size() > 1000);  // a real trial, not two empty files
    CHECK(in_process == test::read_text(processes.dir / log));
  }
  // The cube ends where the three-process trial left it, to the last bit.
  CHECK(summary["objects"]["cube"]["position"] == processes.summary["objects"]["cube"]["position"]);
  CHECK(summary["objects"]["cube"]["position"][0].get<double>() > 0.05);  // and it was pushed
}

// Thumb and index of a two-finger SPIDAR (a string set and a device port each) grasp the grasp scene's cube, lift it
// and put it down under local coupling.
void check_same_grasp(const std::string& name, std::uint64_t phase_ticks) {
  const std::string source = IMPETUS_SOURCE_DIR;
  const test::Trial processes = test::run_trial(
      name + "-processes", "--scene scenes/grasp.json --finger thumb=scenes/grasp_thumb.csv --finger "
                           "index=scenes/grasp_index.csv --clock lockstep --coupling local --phase " +
                               std::to_string(phase_ticks));
  REQUIRE(processes.exit_status == 0);

  InProcessTrialOptions options;
  options.scene_path = source + "/scenes/grasp.json";
  options.fingers = {"thumb=" + source + "/scenes/grasp_thumb.csv", "index=" + source + "/scenes/grasp_index.csv"};
  options.coupling = Coupling::local;
  options.phase_ticks = phase_ticks;
  options.out_dir = test::out_dir(name + "-in-process");
  const nlohmann::json summary = run_in_process_trial(options);

  for (const char* log : {"world.csv", "haptic.csv", "haptic.endpoint1.csv", "device.csv", "device.endpoint1.csv"}) {
    INFO(log);
    const std::string in_process = test::read_text(options.out_dir / log);
    CHECK(in_process.size() > 1000);
    CHECK(in_process == test::read_text(processes.dir / log));
  }
  CHECK(summary["objects"]["cube"]["position"] == processes.summary["objects"]["cube"]["position"]);

  // Each finger's impulse on the cube as the world applied it equals what its servo rendered (the fingers let go
  // 1.5 s before the end, so the totals are final).
  const nlohmann::json& rendered = summary["haptic"]["endpoints"];
  const nlohmann::json& applied = summary["world"]["endpoints"];
  REQUIRE(rendered.size() == 2);
  REQUIRE(applied.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    INFO("endpoint " << k);
    CHECK(applied[k]["endpoint"] == k);
    for (int axis = 0; axis < 3; ++axis) {
      const double rendered_Ns = rendered[k]["impulse_by_object_Ns"]["0"][axis].get<double>();
      const double applied_Ns = applied[k]["impulse_by_object_Ns"]["0"][axis].get<double>();
      CHECK(std::abs(rendered_Ns - applied_Ns) <= 1e-9 * (1.0 + std::abs(rendered_Ns)));
    }
  }
  // The two fingers carried the cube's weight between them while it was lifted: each gave an upward impulse.
  CHECK(applied[0]["impulse_by_object_Ns"]["0"][2].get<double>() > 1.0);
  CHECK(applied[1]["impulse_by_object_Ns"]["0"][2].get<double>() > 1.0);
}

}  // namespace

TEST_CASE("a two-finger grasp in one process equals the grasp in three, bit for bit, and each finger's impulse is "
          "applied as rendered") {
  check_same_grasp("loop-grasp", 20);
}

TEST_CASE("two users on one world in one process equal the same users as five processes, bit for bit") {
  // Users A (the master) and B (following its ticks) press the tap scene's cube from both sides, 4 and 1 mm deep.
  const std::filesystem::path processes = test::two_users("loop-users-processes", 0.004, 0.001);

  InProcessTrialOptions options;
  options.scene_path = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  options.fingers = {"finger=" + (processes / "a.csv").string()};
  options.followers = {{"finger=" + (processes / "b.csv").string()}};
  options.out_dir = test::out_dir("loop-users-in-process");
  const nlohmann::json summary = run_in_process_trial(options);

  const std::string world = test::read_text(options.out_dir / "world.csv");
  CHECK(world.size() > 1000);
  CHECK(world == test::read_text(processes / "world.csv"));
  CHECK(test::read_text(options.out_dir / "haptic.csv") == test::read_text(processes / "haptic_a.csv"));
  CHECK(test::read_text(options.out_dir / "user1.haptic.csv") == test::read_text(processes / "haptic_b.csv"));
  REQUIRE(summary["followers"].size() == 1);
  CHECK(summary["followers"][0]["haptic"]["ticks"].get<int>() > 3000);
}

TEST_CASE("the tap trial in one process equals the tap trial in three, bit for bit (impulse coupling)") {
  check_same_trial("loop-impulse", Coupling::impulse, 17);
}

TEST_CASE("the tap trial in one process equals the tap trial in three, bit for bit (local coupling)") {
  check_same_trial("loop-local", Coupling::local, 0);
}

}  // namespace impetus
