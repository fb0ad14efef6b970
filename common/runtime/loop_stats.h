// SPDX-License-Identifier: Apache-2.0
#pragma once
// Loop statistics every daemon publishes on its link (docs/architecture.md §2: heartbeat and loop statistics), and the
// fixed-size lateness histogram behind the percentiles: recording a sample is O(1) and never allocates, so the 1 kHz
// loop can record every tick.

#include <array>
#include <cstdint>
#include <type_traits>

namespace impetus {

// A snapshot published through a SeqlockChannel; trivially copyable.
struct LoopStats {
  std::int64_t heartbeat_ns = 0;        // CLOCK_MONOTONIC at the last update: a reader calls the loop stale from it
  std::int32_t pid = 0;
  std::uint32_t reserved = 0;
  std::uint64_t ticks = 0;              // loop iterations executed
  std::uint64_t skipped_periods = 0;    // periods missed and skipped (real time only; never replayed in a burst)
  std::uint64_t faults = 0;             // non-finite values replaced by safe ones
  std::uint64_t rejected_frames = 0;    // frames a reader refused (checksum, range, NaN, non-unit normal)
  std::int64_t lateness_p50_ns = 0;     // wake-up lateness past the deadline (real time only)
  std::int64_t lateness_p99_ns = 0;
  std::int64_t lateness_p999_ns = 0;
  std::int64_t lateness_max_ns = 0;
};
static_assert(std::is_trivially_copyable_v<LoopStats>);

// Histogram of non-negative durations: 1 µs bins up to 2 ms (where a healthy 1 kHz loop lives), 100 µs bins up to
// 200 ms (host stalls on this VM reach 60 ms), one overflow bin. Percentiles are bin upper edges, so they overstate a
// value by at most one bin width.
class LatencyHistogram {
 public:
  void record(std::int64_t value_ns);
  std::int64_t percentile_ns(double fraction) const;  // fraction in [0, 1]; 0 if empty
  std::int64_t max_ns() const { return max_ns_; }
  std::uint64_t count() const { return count_; }
  double mean_ns() const { return count_ ? static_cast<double>(sum_ns_) / static_cast<double>(count_) : 0.0; }
  void clear();

 private:
  static constexpr std::int64_t kFineWidthNs = 1'000;
  static constexpr int kFineBins = 2'000;
  static constexpr std::int64_t kCoarseWidthNs = 100'000;
  static constexpr int kCoarseBins = 1'980;
  static constexpr int kBins = kFineBins + kCoarseBins + 1;

  static int bin_of(std::int64_t value_ns);
  static std::int64_t upper_edge_ns(int bin);

  std::array<std::uint64_t, kBins> counts_{};
  std::uint64_t count_ = 0;
  std::int64_t sum_ns_ = 0;
  std::int64_t max_ns_ = 0;
};

std::int64_t monotonic_now_ns();
// CPU time consumed by the calling thread (CLOCK_THREAD_CPUTIME_ID): what a step costs, whatever else the machine does.
std::int64_t thread_cpu_now_ns();

}  // namespace impetus
