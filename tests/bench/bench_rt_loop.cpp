// SPDX-License-Identifier: Apache-2.0
// Real-time loop lateness at 1 kHz: runs RealtimeClock for SECONDS with ordinary scheduling, then again with
// SCHED_FIFO + mlockall (if granted), and prints wake-up lateness p50/p99/p99.9/max and skipped periods for each.
// Asserts nothing: this VM has host stalls of tens of milliseconds; the numbers are the result.
//
//   bench_rt_loop [SECONDS=10] [RATE_HZ=1000]

#include "common/runtime/realtime_clock.h"

#include <sched.h>
#include <sys/mman.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

void measure(const char* label, double seconds, double rate_hz) {
  impetus::RealtimeClock clock(1.0 / rate_hz);
  const auto ticks = static_cast<std::uint64_t>(seconds * rate_hz);
  while (clock.ticks() + clock.skipped_periods() < ticks) clock.wait_next();
  const auto& lateness = clock.lateness();
  std::printf("%-22s %6llu ticks  lateness p50 %7.1f us  p99 %7.1f us  p99.9 %8.1f us  max %8.1f us  "
              "skipped periods %llu\n",
              label, static_cast<unsigned long long>(clock.ticks()), lateness.percentile_ns(0.5) / 1e3,
              lateness.percentile_ns(0.99) / 1e3, lateness.percentile_ns(0.999) / 1e3, lateness.max_ns() / 1e3,
              static_cast<unsigned long long>(clock.skipped_periods()));
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const double rate_hz = argc > 2 ? std::atof(argv[2]) : 1000.0;
  if (!(seconds > 0.0) || !(rate_hz > 0.0)) {
    std::fprintf(stderr, "usage: bench_rt_loop [SECONDS>0] [RATE_HZ>0]\n");
    return 2;
  }
  std::printf("real-time loop at %.0f Hz for %.0f s each:\n", rate_hz, seconds);
  measure("SCHED_OTHER", seconds, rate_hz);
  const std::string warning = impetus::request_realtime(80);
  if (!warning.empty()) std::printf("(%s)\n", warning.c_str());
  measure(warning.empty() ? "SCHED_FIFO+mlockall" : "FIFO/mlock partial", seconds, rate_hz);
  return 0;
}
