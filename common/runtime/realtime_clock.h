// SPDX-License-Identifier: Apache-2.0
#pragma once
// The real-time clock of a periodic loop (docs/architecture.md §3, `--clock realtime`).
//
// Deadlines are absolute (clock_nanosleep with TIMER_ABSTIME on CLOCK_MONOTONIC), so lateness in one period does not
// shift the next. When the loop wakes more than a period late (a host stall: up to 60 ms on this VM) the missed periods
// are skipped and counted, not replayed in a burst: a burst would run the servo many times on one stale device reading
// and hand the physics a compressed time base. Each tick reports the real elapsed time so the force's damping term and
// the impulse integral use the time that actually passed.

#include "common/runtime/loop_stats.h"

#include <cstdint>
#include <string>

namespace impetus {

struct TickTiming {
  std::uint64_t index = 0;        // ticks executed so far, this one included minus one (first tick is 0)
  double now_s = 0.0;             // time since the clock started
  double elapsed_s = 0.0;         // real time since the previous tick (the period on the first tick)
  std::int64_t lateness_ns = 0;   // how far past its deadline this tick woke
  std::uint64_t skipped = 0;      // periods skipped before this tick
};

class RealtimeClock {
 public:
  explicit RealtimeClock(double period_s);

  // Sleeps until the next deadline and returns this tick's timing. Never allocates.
  TickTiming wait_next();

  double period_s() const { return period_s_; }
  const LatencyHistogram& lateness() const { return lateness_; }
  std::uint64_t skipped_periods() const { return skipped_total_; }
  std::uint64_t ticks() const { return ticks_; }

 private:
  double period_s_;
  std::int64_t period_ns_;
  std::int64_t start_ns_ = 0;
  std::int64_t next_deadline_ns_ = 0;
  std::int64_t previous_wake_ns_ = 0;
  std::uint64_t ticks_ = 0;
  std::uint64_t skipped_total_ = 0;
  LatencyHistogram lateness_;
};

// A statistics snapshot of the calling process: heartbeat now, pid, and — given the clock of a real-time loop — its
// wake-up lateness and skipped periods. The caller adds its own counters (ticks, faults, rejected frames).
LoopStats loop_stats_now(const RealtimeClock* clock);

// Asks for SCHED_FIFO at `priority`, locks memory (mlockall) and sets a 1 ns timer slack for the calling thread.
// Returns "" if everything was granted, else a warning naming what was refused and why; the caller prints it and
// carries on (docs/architecture.md §3).
std::string request_realtime(int fifo_priority);

}  // namespace impetus
