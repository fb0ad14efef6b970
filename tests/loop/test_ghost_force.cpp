// SPDX-License-Identifier: Apache-2.0
// What the finger feels between world frames, scored against the true geometry (tests/support/ghost_score.h): the
// goals are no ghost force beyond 1 % of the contact ticks, release within 2 ms, no lost wall and no pop-through.
// Sparse clutter meets them and is asserted here; the denser clutters' figures, which do not yet, are printed by
// build/tests/bench_ghost_force (docs/ghost_force.md).

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

}  // namespace impetus
