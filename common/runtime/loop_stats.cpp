// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/loop_stats.h"

#include <time.h>

#include <algorithm>
#include <cmath>

namespace impetus {

std::int64_t monotonic_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

std::int64_t thread_cpu_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

int LatencyHistogram::bin_of(std::int64_t value_ns) {
  const std::int64_t value = std::max<std::int64_t>(value_ns, 0);
  if (value < kFineWidthNs * kFineBins) return static_cast<int>(value / kFineWidthNs);
  const std::int64_t coarse = (value - kFineWidthNs * kFineBins) / kCoarseWidthNs;
  return coarse < kCoarseBins ? kFineBins + static_cast<int>(coarse) : kBins - 1;
}

std::int64_t LatencyHistogram::upper_edge_ns(int bin) {
  if (bin < kFineBins) return (bin + 1) * kFineWidthNs;
  return kFineWidthNs * kFineBins + (bin - kFineBins + 1) * kCoarseWidthNs;
}

void LatencyHistogram::record(std::int64_t value_ns) {
  ++counts_[bin_of(value_ns)];
  ++count_;
  sum_ns_ += value_ns;
  max_ns_ = std::max(max_ns_, value_ns);
}

std::int64_t LatencyHistogram::percentile_ns(double fraction) const {
  if (count_ == 0) return 0;
  const double clamped = std::clamp(fraction, 0.0, 1.0);
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(clamped * count_)));
  std::uint64_t seen = 0;
  for (int bin = 0; bin < kBins; ++bin) {
    seen += counts_[bin];
    // The overflow bin has no upper edge: report the largest sample instead.
    if (seen >= rank) return bin == kBins - 1 ? max_ns_ : std::min(upper_edge_ns(bin), max_ns_);
  }
  return max_ns_;
}

void LatencyHistogram::clear() {
  counts_.fill(0);
  count_ = 0;
  sum_ns_ = 0;
  max_ns_ = 0;
}

}  // namespace impetus
