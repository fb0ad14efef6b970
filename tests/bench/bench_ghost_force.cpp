// SPDX-License-Identifier: Apache-2.0
// Ghost force, release, lost walls and pop-through at 20 and 10 Hz worlds, scored against the true geometry
// (tests/support/ghost_score.h): static clutter of boxes, capsules, cylinders and spheres, and streams of them sliding
// past the finger under each coupling, on every engine; then the same made users' meshes (tests/support/
// mesh_clutter.h), with and without bowls. Prints; asserts nothing (tests/loop/test_ghost_force.cpp asserts the goals).

#include "tests/support/ghost_score.h"
#include "tests/support/mesh_clutter.h"

#include <cstdio>
#include <string>

namespace {

void print_row(const char* what, int count, double rate_hz, const impetus::test::Score& s) {
  std::printf("%-26s %8d %8.0f %10d %7d, %5.2f %10d %12d %14.0f\n", what, count, rate_hz, s.contact_ticks,
              s.ghost_ticks, 100.0 * s.ghost_fraction(), s.lost_wall_ticks, s.pop_through_ticks, s.worst_release_ms);
  std::fflush(stdout);
}

}  // namespace

int main() {
  using impetus::Coupling;
  namespace test = impetus::test;
  std::printf("%-26s %8s %8s %10s %14s %10s %12s %14s\n", "scene", "objects", "world", "contact", "ghost", "lost wall",
              "pop-through", "worst release");
  std::printf("%-26s %8s %8s %10s %14s %10s %12s %14s\n", "", "[/cube]", "[Hz]", "[ticks]", "[ticks, %]", "[ticks]",
              "[ticks]", "[ms]");
  for (const double rate_hz : {20.0, 10.0}) {
    for (const int count : {4, 16, 64}) {
      print_row("static clutter", count, rate_hz, test::score(test::clutter(count, 7), rate_hz, 20.0));
    }
  }
  // The stream: 0.1 m/s, 17° off the x axis, boxes spinning at 1 rad/s; on every engine (the clutter is static, so
  // no engine moves it).
  for (const impetus::EngineEntry& entry : impetus::engine_entries()) {
    for (const Coupling coupling : {Coupling::impulse, Coupling::position, Coupling::local}) {
      const std::string what = std::string("stream, ") + impetus::to_string(coupling) + ", " + std::string(entry.name);
      for (const double rate_hz : {20.0, 10.0}) {
        for (const int count : {4, 16}) {
          impetus::Scene scene = test::stream(count, 7, Eigen::Vector3d(0.1, 0.03, 0.0), 1.0, 20.0);
          scene.physics.engine = std::string(entry.name);
          print_row(what.c_str(), count, rate_hz, test::score(scene, rate_hz, 20.0, coupling));
        }
      }
    }
  }
  // Users' meshes (ODE): the clutter with and without bowls (open, thin-walled), and a stream of closed meshes.
  for (const double rate_hz : {20.0, 10.0}) {
    for (const int count : {4, 16, 64}) {
      print_row("mesh clutter, closed", count, rate_hz,
                test::score(test::as_meshes(test::clutter(count, 7), false), rate_hz, 20.0));
      print_row("mesh clutter, bowls", count, rate_hz,
                test::score(test::as_meshes(test::clutter(count, 7), true), rate_hz, 20.0));
    }
  }
  for (const Coupling coupling : {Coupling::impulse, Coupling::position, Coupling::local}) {
    const std::string what = std::string("mesh stream, ") + impetus::to_string(coupling);
    for (const double rate_hz : {20.0, 10.0}) {
      const impetus::Scene scene =
          test::as_meshes(test::stream(4, 7, Eigen::Vector3d(0.1, 0.03, 0.0), 1.0, 20.0), false);
      print_row(what.c_str(), 4, rate_hz, test::score(scene, rate_hz, 20.0, coupling));
    }
  }
  return 0;
}
