// SPDX-License-Identifier: Apache-2.0
// Ghost force, release, lost walls and pop-through in static clutter of boxes, capsules, cylinders and spheres, at 20
// and 10 Hz worlds, scored against the true geometry (tests/support/ghost_score.h). Prints; asserts nothing (the
// sparse case is asserted in tests/loop/test_ghost_force.cpp).

#include "tests/support/ghost_score.h"

#include <cstdio>

int main() {
  std::printf("%8s %8s %10s %14s %10s %12s %14s\n", "objects", "world", "contact", "ghost", "lost wall", "pop-through",
              "worst release");
  std::printf("%8s %8s %10s %14s %10s %12s %14s\n", "", "[Hz]", "[ticks]", "[ticks, %]", "[ticks]", "[ticks]", "[ms]");
  for (const double rate_hz : {20.0, 10.0}) {
    for (const int count : {4, 16, 64}) {
      const impetus::test::Score s = impetus::test::score(impetus::test::clutter(count, 7), rate_hz, 20.0);
      std::printf("%8d %8.0f %10d %7d, %5.2f %10d %12d %14.0f\n", count, rate_hz, s.contact_ticks, s.ghost_ticks,
                  100.0 * s.ghost_fraction(), s.lost_wall_ticks, s.pop_through_ticks, s.worst_release_ms);
    }
  }
  return 0;
}
