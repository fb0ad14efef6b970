// SPDX-License-Identifier: Apache-2.0
#include "world_manager/impulse_ledger.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"
#include "common/link/shm/wire_frames.h"
#include "tests/common/test_support.h"

#include <catch2/catch.hpp>

#include <time.h>

#include <atomic>
#include <random>

namespace impetus {
namespace {

struct ReportLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;
  SegmentHeader header;
  SeqlockChannel<wire::HapticReport> report;
  std::atomic<std::uint32_t> writer_done{0};
  Vec3 rendered_total_Ns[4]{};  // what the writer rendered per object, published when it is done
};

void sleep_ns(long ns) {
  timespec duration{ns / 1'000'000'000, ns % 1'000'000'000};
  nanosleep(&duration, nullptr);
}

// Impulses are whole multiples of 2^-20 N·s and totals stay far below 2^32 of them, so every sum below is exact in
// double precision: the test can demand equality, and a single lost or doubled tick shows as a mismatch.
constexpr double kQuantum_Ns = 1.0 / (1 << 20);

}  // namespace

TEST_CASE("impulse applied by a reader at random 5-100 Hz equals impulse rendered by a 1 kHz writer with jitter") {
  const std::string name = test::unique_segment_name("ledger");
  auto segment = Segment<ReportLayout>::create(name);

  const pid_t writer = test::fork_child([&] {
    std::mt19937_64 random(12345);
    std::uniform_int_distribution<int> quanta(-50, 200);
    std::uniform_int_distribution<long> jitter_ns(200'000, 1'800'000);  // 1 kHz on average, ±0.8 ms
    std::uniform_int_distribution<int> object_pick(0, 3);
    HapticReport report{};
    report.haptic_session = 77;
    report.entry_count = 4;
    for (int k = 0; k < 4; ++k) report.entries[k].object_id = k;
    for (std::uint64_t tick = 1; tick <= 1500; ++tick) {
      report.tick = tick;
      ObjectImpulse& entry = report.entries[object_pick(random)];
      for (int a = 0; a < 3; ++a) entry.impulse_Ns[a] += quanta(random) * kQuantum_Ns;
      entry.last_tick = tick;
      wire::HapticReport wire_report;
      encode(report, wire_report);
      segment->report.write(wire_report);
      sleep_ns(jitter_ns(random));
    }
    for (int k = 0; k < 4; ++k) segment->rendered_total_Ns[k] = report.entries[k].impulse_Ns;
    segment->writer_done.store(1, std::memory_order_release);
    return 0;
  });

  ImpulseLedger ledger(4);
  Vec3 applied_Ns[4]{};
  auto consume = [&](const HapticReport& report) {
    for (std::uint32_t k = 0; k < report.entry_count; ++k) {
      const ImpulseDelta delta = ledger.take({report.haptic_session, report.endpoint}, report.entries[k]);
      for (int a = 0; a < 3; ++a) applied_Ns[report.entries[k].object_id][a] += delta.impulse_Ns[a];
    }
  };
  std::mt19937_64 random(999);
  std::uniform_int_distribution<long> period_ns(10'000'000, 200'000'000);  // 5–100 Hz
  std::uint64_t last_sequence = 0;
  wire::HapticReport wire_report{};
  HapticReport report{};
  int reads = 0;
  for (;;) {
    const bool done = segment->writer_done.load(std::memory_order_acquire) != 0;
    // Reading the same report twice must not apply anything twice: read, then read again with a reset sequence.
    if (segment->report.try_read(wire_report, last_sequence) && decode(wire_report, report) == FrameError::ok) {
      consume(report);
      consume(report);
      ++reads;
    }
    if (done) break;
    sleep_ns(period_ns(random));
  }
  REQUIRE(test::wait_child(writer) == 0);
  // One last read after the writer finished: the final totals.
  std::uint64_t any = 0;
  REQUIRE(segment->report.try_read(wire_report, any));
  REQUIRE(decode(wire_report, report) == FrameError::ok);
  consume(report);

  CHECK(reads > 5);
  for (int k = 0; k < 4; ++k) {
    for (int a = 0; a < 3; ++a) CHECK(applied_Ns[k][a] == segment->rendered_total_Ns[k][a]);
  }
}

TEST_CASE("a new haptic session or entry epoch restarts the baseline from zero instead of a burst") {
  ImpulseLedger ledger(2);
  ObjectImpulse entry{};
  entry.object_id = 0;
  entry.impulse_Ns = {5.0, 0, 0};
  CHECK(ledger.take({1, 0}, entry).impulse_Ns.x() == 5.0);
  CHECK(ledger.take({1, 0}, entry).impulse_Ns.x() == 0.0);  // the same total again: nothing new

  // The haptic controller restarts: its new total (0.25) is all new impulse, not 0.25 − 5.
  entry.impulse_Ns = {0.25, 0, 0};
  CHECK(ledger.take({2, 0}, entry).impulse_Ns.x() == 0.25);

  // The entry is re-allocated with a new epoch: same rule.
  entry.epoch = 1;
  entry.impulse_Ns = {0.5, 0, 0};
  CHECK(ledger.take({2, 0}, entry).impulse_Ns.x() == 0.5);

  // The static share follows the session rule too.
  CHECK(ledger.take_static({2, 0}, {0, 0, -1.0}).z() == -1.0);
  CHECK(ledger.take_static({2, 0}, {0, 0, -1.5}).z() == -0.5);
  CHECK(ledger.take_static({3, 0}, {0, 0, -0.25}).z() == -0.25);
}

TEST_CASE("two endpoints pushing one object keep separate baselines") {
  ImpulseLedger ledger(1);
  ObjectImpulse thumb{};
  thumb.object_id = 0;
  ObjectImpulse index = thumb;
  thumb.impulse_Ns = {1.0, 0, 0};
  index.impulse_Ns = {-0.75, 0, 0};
  // Interleaved reports of two fingers of one session: each total is differenced against its own baseline, so the
  // object gets exactly the sum of what the two rendered, reported twice or not.
  CHECK(ledger.take({7, 0}, thumb).impulse_Ns.x() == 1.0);
  CHECK(ledger.take({7, 1}, index).impulse_Ns.x() == -0.75);
  CHECK(ledger.take({7, 0}, thumb).impulse_Ns.x() == 0.0);
  index.impulse_Ns = {-1.0, 0, 0};
  CHECK(ledger.take({7, 1}, index).impulse_Ns.x() == -0.25);
  CHECK(ledger.take({7, 1}, index).impulse_Ns.x() == 0.0);
}

}  // namespace impetus
