// SPDX-License-Identifier: Apache-2.0
// The in-process loop against the three daemons: the same nodes over the in-process links must reproduce a trial
// run through shared memory bit for bit (DESIGN.md §6: the same trial in one process or three gives the same outcome).

#include "tests/integration/trial_support.h"
#include "loop/in_process_trial.h"

#include <catch2/catch.hpp>

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

}  // namespace

TEST_CASE("the tap trial in one process equals the tap trial in three, bit for bit (impulse coupling)") {
  check_same_trial("loop-impulse", Coupling::impulse, 17);
}

TEST_CASE("the tap trial in one process equals the tap trial in three, bit for bit (local coupling)") {
  check_same_trial("loop-local", Coupling::local, 0);
}

}  // namespace impetus
