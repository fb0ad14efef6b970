// SPDX-License-Identifier: Apache-2.0
// Several users on one lockstep world (docs/architecture.md §3: the first haptic controller is the master, the others
// follow its ticks), as separate processes over shared memory: each user a haptic controller with its own device port
// and a simulated finger, all on one world manager.

#include "csv_columns.h"
#include "users_support.h"

#include <catch2/catch.hpp>

#include <cmath>

namespace impetus {
namespace {

using test::two_users;

// User `name`'s impulse on the cube: what its servo rendered and what the world applied from its reports.
struct Impulses {
  double rendered_x_Ns;
  double applied_x_Ns;
};
Impulses impulses_of(const std::filesystem::path& dir, const std::string& name) {
  const auto haptic = test::read_json(dir / ("haptic_" + name + ".json"))["haptic"];
  const auto world = test::read_json(dir / "world.json")["world"]["endpoints"];
  Impulses out{haptic["impulse_by_object_Ns"]["0"][0].get<double>(), 0.0};
  // The world names endpoints by session; the user's is the one whose total matches in sign and size best.
  double best = 1e300;
  for (const auto& endpoint : world) {
    const double applied = endpoint["impulse_by_object_Ns"]["0"][0].get<double>();
    if (std::abs(applied - out.rendered_x_Ns) < best) {
      best = std::abs(applied - out.rendered_x_Ns);
      out.applied_x_Ns = applied;
    }
  }
  return out;
}

}  // namespace

TEST_CASE("two users in lockstep over shared memory: equal pushes hold the cube, the run is bitwise reproducible, "
          "and each user's impulse is applied as rendered") {
  const auto first = two_users("users-equal-1", 0.001, 0.001);
  const auto second = two_users("users-equal-2", 0.001, 0.001);
  const std::string log = test::read_text(first / "world.csv");
  CHECK(log.size() > 1000);
  CHECK(log == test::read_text(second / "world.csv"));  // the follower ticks in a fixed place: the same run twice
  CHECK(test::read_text(first / "haptic_b.csv") == test::read_text(second / "haptic_b.csv"));

  const auto world_log = test::read_csv_columns(first / "world.csv");
  const double moved_m = std::abs(world_log.at("cube.x_m").back() - 0.03);
  INFO("moved " << moved_m * 1e3 << " mm");
  CHECK(moved_m < 0.001);
  for (const char* user : {"a", "b"}) {
    const Impulses impulses = impulses_of(first, user);
    INFO("user " << user << ": rendered " << impulses.rendered_x_Ns << " N·s, applied " << impulses.applied_x_Ns);
    // Each pressed ~0.26 N (the simulated hand's 300 N/m in series with the surface's 2000 N/m, 1 mm) for ~3.5 s.
    CHECK(std::abs(impulses.rendered_x_Ns) > 0.5);
    CHECK(std::abs(impulses.rendered_x_Ns - impulses.applied_x_Ns) <= 1e-9 * std::abs(impulses.rendered_x_Ns));
  }
  CHECK(test::read_json(first / "world.json")["world"]["endpoints"].size() == 2);
}

// The cube slides toward the weaker user until it presses that finger as hard as the stronger one presses it (the
// floor's friction takes the rest): over the run the two totals end close, and the cube has moved toward B.
TEST_CASE("two users in lockstep over shared memory: the stronger push moves the cube toward the weaker user") {
  const auto dir = two_users("users-unequal", 0.006, 0.001);
  const Impulses a = impulses_of(dir, "a"), b = impulses_of(dir, "b");
  const auto world_log = test::read_csv_columns(dir / "world.csv");
  const double moved_m = world_log.at("cube.x_m").back() - 0.03;
  INFO("A applied " << a.applied_x_Ns << " N·s, B " << b.applied_x_Ns << " N·s; the cube moved " << moved_m * 1e3
                    << " mm");
  CHECK(moved_m > 0.001);  // A aimed 6 mm into its side, B 1 mm
  CHECK(std::abs(a.rendered_x_Ns - a.applied_x_Ns) <= 1e-9 * std::abs(a.rendered_x_Ns));
  CHECK(std::abs(b.rendered_x_Ns - b.applied_x_Ns) <= 1e-9 * std::abs(b.rendered_x_Ns));
}

}  // namespace impetus
