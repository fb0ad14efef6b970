// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/loop_stats.h"
#include "common/runtime/realtime_clock.h"

#include <catch2/catch.hpp>

namespace impetus {

TEST_CASE("lateness histogram percentiles are within one bin of the exact values") {
  LatencyHistogram histogram;
  CHECK(histogram.percentile_ns(0.5) == 0);
  for (int k = 1; k <= 1000; ++k) histogram.record(k * 1'000);  // 1 µs … 1 ms
  histogram.record(60'000'000);                                  // one 60 ms host stall
  CHECK(histogram.count() == 1001);
  CHECK(histogram.percentile_ns(0.5) == Approx(501'000).margin(1'000));
  CHECK(histogram.percentile_ns(0.99) == Approx(991'000).margin(1'000));
  CHECK(histogram.percentile_ns(1.0) == 60'000'000);
  CHECK(histogram.max_ns() == 60'000'000);
  histogram.record(5'000'000'000);  // past the last bin: reported as the max, not lost
  CHECK(histogram.percentile_ns(1.0) == 5'000'000'000);
}

TEST_CASE("real-time clock reports elapsed time and skips missed periods instead of bursting") {
  RealtimeClock clock(0.002);
  const TickTiming first = clock.wait_next();
  CHECK(first.index == 0);
  // Stall for ~5 periods: the next tick comes once, late, with the skipped periods counted.
  timespec stall{0, 10'500'000};
  nanosleep(&stall, nullptr);
  const TickTiming late = clock.wait_next();
  CHECK(late.index == 1);
  CHECK(late.skipped >= 4);
  CHECK(late.elapsed_s >= 0.0105);
  // The missed periods were skipped, not replayed: the next tick is the third tick, not the seventh.
  const TickTiming next = clock.wait_next();
  CHECK(next.index == 2);
  CHECK(clock.ticks() == 3);
  CHECK(clock.skipped_periods() >= late.skipped);
}

}  // namespace impetus
