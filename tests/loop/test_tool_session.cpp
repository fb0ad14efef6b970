// SPDX-License-Identifier: Apache-2.0
// A tool in the hand through the whole chain (loop/tool_loop.h): the scene's tool, the simulated 8-string grip
// SPIDAR and the hand holding it, the driver's pose from the counts and tensions from the wrench, the tool servo and
// the world, in lockstep. scenes/peg_in_hole.json: a peg goes down a hole with 0.5 mm of clearance and presses its
// floor, then pushes a free cube.

#include <catch2/catch.hpp>

#include "common/contract/rotation.h"
#include "loop/tool_loop.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace impetus;
using Eigen::Vector3d;

namespace {

const std::string kPegInHole = std::string(IMPETUS_SOURCE_DIR) + "/scenes/peg_in_hole.json";

// A path of grip positions (orientation held level) through `points`, each leg taking `seconds` of 1 ms ticks.
std::vector<GripPose> path(const std::vector<Vector3d>& points, double seconds) {
  std::vector<GripPose> out;
  const int ticks = static_cast<int>(std::lround(seconds / 1e-3));
  for (std::size_t leg = 0; leg + 1 < points.size(); ++leg) {
    for (int i = 1; i <= ticks; ++i) {
      const double s = static_cast<double>(i) / ticks;
      out.push_back({points[leg] + s * (points[leg + 1] - points[leg]), Eigen::Quaterniond::Identity()});
    }
  }
  return out;
}

ToolLoopOptions peg_options(Coupling coupling) {
  ToolLoopOptions options;
  options.scene_path = kPegInHole;
  options.coupling = coupling;
  options.start.position_m = Vector3d(0.0, 0.0, 0.1);  // the peg's tip 2 cm above the hole's rim
  return options;
}

std::vector<ToolTick> play(ToolLoop& loop, const std::vector<GripPose>& targets) {
  std::vector<ToolTick> out(targets.size());
  loop.step(targets.size(), targets, out);
  return out;
}

}  // namespace

TEST_CASE("tool session: the peg goes down the hole through the 8-string device and presses its floor, touching no "
          "wall", "[loop][tool]") {
  ToolLoop loop(peg_options(Coupling::local));
  // Down from 2 cm above the rim to 5 mm below the hole's floor in 1 s, held 0.5 s.
  std::vector<GripPose> targets = path({Vector3d(0, 0, 0.1), Vector3d(0, 0, 0.045), Vector3d(0, 0, 0.045)}, 0.5);
  const std::vector<ToolTick> ticks = play(loop, targets);
  double worst_pose_m = 0.0, worst_wall_m = 0.0, lowest_tip_m = 1.0, worst_strings_N = 0.0;
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const ToolTick& tick = ticks[i];
    // The driver's pose from quantised counts (17 µm a count) against the hand's true grip when they were read.
    worst_pose_m = std::max(worst_pose_m, (tick.grip.position_m - tick.hand.position_m).norm());
    // The proxy's peg: its tip above the floor, and below the rim inside the hole's 0.5 mm of clearance.
    const double tip_m = tick.proxy.position_m.z() - 0.05;
    lowest_tip_m = std::min(lowest_tip_m, tip_m);
    if (tip_m < 0.03) {
      worst_wall_m = std::max({worst_wall_m, std::abs(tick.proxy.position_m.x()) - 0.0005,
                               std::abs(tick.proxy.position_m.y()) - 0.0005});
    }
    if (i > 0) worst_strings_N = std::max(worst_strings_N, (tick.strings_force_N - ticks[i - 1].force_N).norm());
  }
  CHECK(worst_pose_m < 2e-5);  // the kinematics' 11 µm at worst over the working volume (test_grip.cpp)
  CHECK(lowest_tip_m > -1e-9);
  CHECK(worst_wall_m < 1e-9);
  // Each tick's strings render the command of the tick before (the port holds it over the device's tick), to what
  // the pose's quantisation and the tick's motion leave: the strings pull at the true pose, the driver's wrench
  // matrix is the measured one's (below). Moving, that is ~1.5 mN.
  CHECK(worst_strings_N < 0.01);
  // Held still, each tick's strings render the command of the tick before (the port's one-tick hold) to what the
  // pose's quantisation leaves: the strings pull at the true pose and the driver's wrench matrix is the measured
  // one's, ~10 µm off, which turns a few newtons in each string by ~10⁻⁵ rad. (The command itself dithers by a count's
  // k·δ + b·δ/T ≈ 0.06 N where the hand rests on a count's edge.)
  double held_strings_N = 0.0;
  for (std::size_t i = ticks.size() - 300; i < ticks.size(); ++i) {
    held_strings_N = std::max(held_strings_N, (ticks[i].strings_force_N - ticks[i - 1].force_N).norm());
  }
  CHECK(held_strings_N < 1e-3);
  const ToolTick& last = ticks.back();
  // Held at rest, the floor pushes the peg up with what the hand's spring holds against it; the walls, nothing.
  CHECK(last.force_N.z() > 0.5);
  CHECK(last.force_N.head<2>().norm() < 1e-6 * last.force_N.z());
  CHECK(last.torque_Nm.norm() < 1e-6);
  const nlohmann::json& summary = loop.finish();
  CHECK(summary["device"]["bad_readings"] == 0);
  CHECK(summary["device"]["saturations"] == 0);
  CHECK(summary["tool"]["faults"] == 0);
}

TEST_CASE("tool session: the peg pushes a free cube: the cube slides, and the world applies the impulse the tool "
          "rendered, under both couplings", "[loop][tool]") {
  for (const Coupling coupling : {Coupling::local, Coupling::impulse}) {
    CAPTURE(to_string(coupling));
    ToolLoop loop(peg_options(coupling));
    // Over to the cube's side, the tip 2 cm above the floor (the cube's middle height is 1.5 cm), then 2.5 cm on.
    const std::vector<GripPose> targets = path({Vector3d(0, 0, 0.1), Vector3d(0.04, 0, 0.07), Vector3d(0.075, 0, 0.07),
                                                Vector3d(0.075, 0, 0.07)}, 0.5);
    const std::vector<ToolTick> ticks = play(loop, targets);
    const double peak_N = std::max_element(ticks.begin(), ticks.end(), [](const ToolTick& a, const ToolTick& b) {
      return a.force_N.norm() < b.force_N.norm();
    })->force_N.norm();
    CHECK(peak_N > 0.1);
    const nlohmann::json summary = loop.finish();
    const ToolLoopObject cube = loop.objects().back();
    CHECK(cube.pose.position_m.x() > 0.085);  // pushed 5 mm or more
    const nlohmann::json& ledger = summary["ledger"]["cube"];
    for (int i = 0; i < 3; ++i) {
      CHECK(ledger["applied_Ns"][i].get<double>() == Approx(ledger["rendered_Ns"][i].get<double>()).margin(1e-12));
      CHECK(ledger["applied_Nms"][i].get<double>() == Approx(ledger["rendered_Nms"][i].get<double>()).margin(1e-12));
    }
    CHECK(ledger["rendered_Ns"][0].get<double>() > 0.01);
  }
}

TEST_CASE("tool session: two runs are bitwise the same", "[loop][tool]") {
  const auto run = [] {
    ToolLoop loop(peg_options(Coupling::local));
    const std::vector<GripPose> targets = path({Vector3d(0, 0, 0.1), Vector3d(0.04, 0, 0.07), Vector3d(0.07, 0.01,
                                                0.07)}, 0.4);
    const std::vector<ToolTick> ticks = play(loop, targets);
    loop.finish();
    return std::make_pair(ticks.back().force_N, loop.objects().back().pose.position_m);
  };
  const auto a = run(), b = run();
  CHECK(a.first == b.first);
  CHECK(a.second == b.second);
}

TEST_CASE("tool session: refusals name what is wrong", "[loop][tool]") {
  ToolLoopOptions options = peg_options(Coupling::position);
  CHECK_THROWS_WITH(ToolLoop(options), Catch::Contains("position coupling"));
  options = peg_options(Coupling::local);
  options.scene_path.clear();
  options.scene_text = R"({"objects": []})";
  CHECK_THROWS_WITH(ToolLoop(options), Catch::Contains("no \"tool\" block"));
  options = peg_options(Coupling::local);
  options.world_rate_hz = 30.0;
  CHECK_THROWS_WITH(ToolLoop(options), Catch::Contains("whole number of 1 ms ticks"));
  options = peg_options(Coupling::local);
  options.start.position_m = Vector3d(0.5, 0.0, 0.05);
  CHECK_THROWS_WITH(ToolLoop(options), Catch::Contains("start"));
  ToolLoop loop(peg_options(Coupling::local));
  CHECK_THROWS_WITH(loop.set_target({Vector3d(0, 0, 0.9), Eigen::Quaterniond::Identity()}), Catch::Contains("target"));
}
