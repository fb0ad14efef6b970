// SPDX-License-Identifier: Apache-2.0
// Channel latency between two processes: a writer publishes a HapticReport-sized frame every millisecond with its
// CLOCK_MONOTONIC send time inside; a reader in another process polls the sequence word and records publish→observe
// latency. Prints p50/p99/max; asserts nothing (timing on a shared VM is a measurement, not a test).
//
//   bench_channel [SECONDS=5]

#include "common/link/shm/wire_frames.h"
#include "common/runtime/loop_stats.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

struct BenchLayout {
  static constexpr impetus::SegmentKind kKind = impetus::SegmentKind::world_link;
  impetus::SegmentHeader header;
  impetus::SeqlockChannel<impetus::wire::HapticReport> channel;
  impetus::SeqlockChannel<impetus::wire::HapticReport> spare;  // for the publish cost, read by nobody
  std::atomic<std::uint32_t> stop{0};
  std::atomic<std::uint32_t> reader_ready{0};
};

}  // namespace

int main(int argc, char** argv) {
  using namespace impetus;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  if (!(seconds > 0.0)) {
    std::fprintf(stderr, "usage: bench_channel [SECONDS>0]\n");
    return 2;
  }
  const std::string name = "impetus_bench_channel_" + std::to_string(getpid());
  auto segment = Segment<BenchLayout>::create(name);

  const pid_t reader = fork();
  if (reader == 0) {
    LatencyHistogram latency;
    wire::HapticReport report{};
    std::uint64_t last = 0;
    segment->reader_ready.store(1);
    while (segment->stop.load(std::memory_order_relaxed) == 0) {
      if (segment->channel.try_read(report, last)) {
        latency.record(monotonic_now_ns() - static_cast<std::int64_t>(report.tick));
      }
    }
    std::printf("channel publish->observe latency (HapticReport with 1 entry: %zu of its %zu bytes, %llu samples): "
                "p50 %.2f us, p99 %.2f us, p99.9 %.2f us, max %.1f us\n",
                used_bytes(report), sizeof(wire::HapticReport), static_cast<unsigned long long>(latency.count()),
                latency.percentile_ns(0.5) / 1e3, latency.percentile_ns(0.99) / 1e3,
                latency.percentile_ns(0.999) / 1e3, latency.max_ns() / 1e3);
    std::fflush(stdout);
    _exit(0);
  }
  while (segment->reader_ready.load() == 0) usleep(1000);

  // What publishing a report costs the haptic loop (encode, seal, write the used bytes), by entries in use.
  for (const std::uint32_t entries : {1u, 8u, kMaxImpulseEntries}) {
    HapticReport contract{};
    contract.entry_count = entries;
    wire::HapticReport out{};
    constexpr int kRepeats = 200000;
    const std::int64_t start = monotonic_now_ns();
    for (int i = 0; i < kRepeats; ++i) {
      contract.tick = static_cast<std::uint64_t>(i);
      encode(contract, out);
      segment->spare.write(out, used_bytes(out));
    }
    const double ns = static_cast<double>(monotonic_now_ns() - start) / kRepeats;
    std::printf("report publish (encode + seal + write), %2u entries, %5zu bytes: %.0f ns\n", entries,
                used_bytes(out), ns);
  }

  wire::HapticReport report{};
  report.entry_count = 1;
  const std::int64_t end = monotonic_now_ns() + static_cast<std::int64_t>(seconds * 1e9);
  while (monotonic_now_ns() < end) {
    report.tick = static_cast<std::uint64_t>(monotonic_now_ns());  // the send time travels in the frame
    report.checksum = frame_checksum(report);
    segment->channel.write(report, used_bytes(report));
    usleep(1000);
  }
  segment->stop.store(1);
  int status = 0;
  waitpid(reader, &status, 0);
  return 0;
}
