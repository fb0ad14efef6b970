// SPDX-License-Identifier: Apache-2.0
// What the finger feels between world frames, scored against the true geometry (tests/support/ghost_score.h): the
// goals are no ghost force beyond 1 % of the contact ticks, release within 2 ms, no lost wall and no pop-through.
// Sparse clutter meets them all and is asserted here; denser clutter meets the ghost goal, asserted too, and its
// releases, lost walls and pop-through are printed by build/tests/bench_ghost_force (docs/ghost_force.md).

#include "tests/support/ghost_score.h"

#include <catch2/catch.hpp>

namespace impetus {

TEST_CASE("between world frames the finger feels sparse clutter as it is: no ghost force, release within 2 ms, no lost "
          "wall, no pop-through") {
  for (const double rate_hz : {20.0, 10.0}) {
    INFO(rate_hz << " Hz world");
    const test::Score s = test::score(test::clutter(4, 7), rate_hz, 20.0);
    CHECK(s.contact_ticks > 100);  // the finger really went through the objects
    CHECK(s.ghost_fraction() <= 0.01);
    CHECK(s.worst_release_ms <= 2.0);
    CHECK(s.lost_wall_ticks == 0);
    CHECK(s.pop_through_ticks == 0);
  }
}

TEST_CASE("between world frames no ghost force lingers in clutter of 16 and 64 objects at 20 and 10 Hz") {
  // An edge's or a rim's plane from the world, kept over its face, hung in free space above the face: 1.8-6.8 % ghost
  // ticks and releases of 17-56 ms in 64 objects before it became the face's plane there (docs/ghost_force.md).
  for (const int count : {16, 64}) {
    for (const double rate_hz : {20.0, 10.0}) {
      INFO(count << " objects, " << rate_hz << " Hz world");
      const test::Score s = test::score(test::clutter(count, 7), rate_hz, 20.0);
      CHECK(s.contact_ticks > 500);
      CHECK(s.ghost_fraction() <= 0.01);
    }
  }
}

}  // namespace impetus
