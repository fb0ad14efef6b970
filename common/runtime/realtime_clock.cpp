// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/realtime_clock.h"

#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace impetus {
namespace {

timespec to_timespec(std::int64_t ns) {
  timespec ts{};
  ts.tv_sec = ns / 1'000'000'000;
  ts.tv_nsec = ns % 1'000'000'000;
  return ts;
}

}  // namespace

RealtimeClock::RealtimeClock(double period_s)
    : period_s_(period_s), period_ns_(std::llround(period_s * 1e9)) {
  if (!(period_s > 0.0) || period_ns_ <= 0) throw std::invalid_argument("clock period must be positive");
  start_ns_ = monotonic_now_ns();
  next_deadline_ns_ = start_ns_ + period_ns_;
  previous_wake_ns_ = start_ns_;
}

TickTiming RealtimeClock::wait_next() {
  const timespec deadline = to_timespec(next_deadline_ns_);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
  const std::int64_t wake_ns = monotonic_now_ns();
  TickTiming timing;
  timing.lateness_ns = wake_ns - next_deadline_ns_;
  // Skip whole periods we slept through; the next deadline is the first one still in the future.
  if (timing.lateness_ns >= period_ns_) {
    timing.skipped = static_cast<std::uint64_t>(timing.lateness_ns / period_ns_);
    next_deadline_ns_ += static_cast<std::int64_t>(timing.skipped) * period_ns_;
    skipped_total_ += timing.skipped;
  }
  next_deadline_ns_ += period_ns_;
  lateness_.record(timing.lateness_ns);
  timing.index = ticks_++;
  timing.now_s = static_cast<double>(wake_ns - start_ns_) * 1e-9;
  timing.elapsed_s = static_cast<double>(wake_ns - previous_wake_ns_) * 1e-9;
  previous_wake_ns_ = wake_ns;
  return timing;
}

LoopStats loop_stats_now(const RealtimeClock* clock) {
  LoopStats stats;
  stats.heartbeat_ns = monotonic_now_ns();
  stats.pid = static_cast<std::int32_t>(getpid());
  if (clock) {
    stats.skipped_periods = clock->skipped_periods();
    stats.lateness_p50_ns = clock->lateness().percentile_ns(0.5);
    stats.lateness_p99_ns = clock->lateness().percentile_ns(0.99);
    stats.lateness_p999_ns = clock->lateness().percentile_ns(0.999);
    stats.lateness_max_ns = clock->lateness().max_ns();
  }
  return stats;
}

std::string request_realtime(int fifo_priority) {
  std::string warning;
  prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);  // default slack (50 µs) would add directly to every wake-up
  sched_param param{};
  param.sched_priority = fifo_priority;
  if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
    warning += std::string("SCHED_FIFO refused (") + std::strerror(errno) + "); ";
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    warning += std::string("mlockall refused (") + std::strerror(errno) + "); ";
  }
  if (!warning.empty()) warning += "running with ordinary scheduling: expect more wake-up jitter";
  return warning;
}

}  // namespace impetus
