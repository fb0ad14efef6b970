// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/lockstep.h"
#include "common/link/shm/segment.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <signal.h>

#include <array>
#include <cstring>
#include <atomic>
#include <vector>

namespace impetus {
namespace {

constexpr int kMaxEvents = 4096;

// Events are encoded as who·10^6 + tick: 1 = device turn, 2 = haptic tick, 3 = world step.
struct LockstepLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;
  SegmentHeader header;
  LockstepTurn device_turn;
  LockstepTurn world_turn;
  std::atomic<std::uint32_t> event_count{0};
  std::array<std::int64_t, kMaxEvents> events{};
  std::atomic<std::uint32_t> idle_work_done{0};  // units of idle work a follower did while it waited
};

void record(LockstepLayout& layout, int who, std::uint64_t tick) {
  const std::uint32_t index = layout.event_count.fetch_add(1);
  if (index < kMaxEvents) layout.events[index] = who * 1'000'000 + static_cast<std::int64_t>(tick);
}

int follow(LockstepLayout& layout, LockstepTurn& turn, int who) {
  for (;;) {
    const TurnResult result = turn.wait_turn([] { return getppid() != 1; });
    if (result == TurnResult::shutdown) return 0;
    if (result != TurnResult::ok) return 1;
    record(layout, who, turn.tick());
    turn.finish();
  }
}

// One run of three processes: the test process is the haptic master, two children follow. Returns the event order.
std::vector<std::int64_t> run_three_processes(std::uint64_t ticks, std::uint64_t ticks_per_step,
                                              std::uint64_t phase) {
  const std::string name = test::unique_segment_name("lockstep");
  auto segment = Segment<LockstepLayout>::create(name);
  const pid_t device = test::fork_child([&] { return follow(*segment, segment->device_turn, 1); });
  const pid_t world = test::fork_child([&] { return follow(*segment, segment->world_turn, 3); });
  auto alive = [](pid_t pid) { return [pid] { return kill(pid, 0) == 0; }; };

  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    segment->device_turn.give(tick);
    REQUIRE(segment->device_turn.wait_done(alive(device), 10.0) == TurnResult::ok);
    record(*segment, 2, tick);
    if (tick >= phase && (tick - phase) % ticks_per_step == 0) {
      segment->world_turn.give(tick);
      REQUIRE(segment->world_turn.wait_done(alive(world), 10.0) == TurnResult::ok);
    }
  }
  segment->device_turn.request_shutdown();
  segment->world_turn.request_shutdown();
  CHECK(test::wait_child(device) == 0);
  CHECK(test::wait_child(world) == 0);
  const std::uint32_t count = segment->event_count.load();
  REQUIRE(count <= kMaxEvents);
  return {segment->events.begin(), segment->events.begin() + count};
}

}  // namespace

TEST_CASE("lockstep with three processes runs device, haptic and world in a fixed order, identical across runs") {
  constexpr std::uint64_t kTicks = 500, kTicksPerStep = 50, kPhase = 17;
  const auto first = run_three_processes(kTicks, kTicksPerStep, kPhase);
  const auto second = run_three_processes(kTicks, kTicksPerStep, kPhase);

  std::vector<std::int64_t> expected;
  for (std::uint64_t tick = 0; tick < kTicks; ++tick) {
    expected.push_back(1'000'000 + static_cast<std::int64_t>(tick));
    expected.push_back(2'000'000 + static_cast<std::int64_t>(tick));
    if (tick >= kPhase && (tick - kPhase) % kTicksPerStep == 0) {
      expected.push_back(3'000'000 + static_cast<std::int64_t>(tick));
    }
  }
  CHECK(first == expected);
  CHECK(second == first);
}

TEST_CASE("a follower does its idle work while it waits, every unit of it, and still takes every turn in order") {
  constexpr std::uint32_t kUnits = 300;  // like rows of a log queued for writing
  constexpr std::uint64_t kTicks = 400;
  const std::string name = test::unique_segment_name("idle");
  auto segment = Segment<LockstepLayout>::create(name);
  const pid_t follower = test::fork_child([&] {
    LockstepLayout& layout = *segment;
    const LockstepIdleWork idle(
        [](void* context) {
          auto& done = static_cast<LockstepLayout*>(context)->idle_work_done;
          if (done.load() >= kUnits) return false;
          done.fetch_add(1);
          return true;
        },
        &layout);
    return follow(layout, layout.device_turn, 1);
  });
  const auto alive = [follower] { return kill(follower, 0) == 0; };
  for (std::uint64_t tick = 0; tick < kTicks; ++tick) {
    segment->device_turn.give(tick);
    REQUIRE(segment->device_turn.wait_done(alive, 10.0) == TurnResult::ok);
  }
  // The follower waits for the next turn: long enough to finish its work, which it does before it would block.
  for (int k = 0; k < 1000 && segment->idle_work_done.load() < kUnits; ++k) usleep(1000);
  segment->device_turn.request_shutdown();
  CHECK(test::wait_child(follower) == 0);
  CHECK(segment->idle_work_done.load() == kUnits);
  const std::uint32_t count = segment->event_count.load();
  REQUIRE(count == kTicks);
  int out_of_order = 0;
  for (std::uint32_t k = 0; k < count; ++k) out_of_order += segment->events[k] == 1'000'000 + k ? 0 : 1;
  CHECK(out_of_order == 0);
}

TEST_CASE("a lockstep master notices a dead follower instead of hanging") {
  const std::string name = test::unique_segment_name("deadfollower");
  auto segment = Segment<LockstepLayout>::create(name);
  const pid_t follower = test::fork_child([] { return 0; });  // exits at once, never takes a turn
  REQUIRE(test::wait_child(follower) == 0);
  segment->device_turn.give(0);
  CHECK(segment->device_turn.wait_done([&] { return kill(follower, 0) == 0; }, 5.0) == TurnResult::peer_gone);
}

TEST_CASE("a scribbled turn is reported as corrupted, never aborts, in either direction") {
  // With POSIX semaphores glibc aborted the whole process ("The futex facility returned an unexpected error code")
  // when another process had written over a sem_t. Every byte pattern here must give `corrupted` or a clean result.
  for (const unsigned char pattern : {0xFF, 0xAB, 0x02, 0x80}) {
    INFO("pattern " << static_cast<int>(pattern));
    const std::string name = test::unique_segment_name("scribble");
    auto segment = Segment<LockstepLayout>::create(name);
    std::memset(static_cast<void*>(&segment->device_turn), pattern, sizeof(LockstepTurn));
    CHECK(segment->device_turn.wait_turn([] { return true; }) == TurnResult::corrupted);
    CHECK(segment->device_turn.wait_done([] { return true; }, 0.2) == TurnResult::corrupted);
    // The master's posts on a scribbled turn do not abort either, and a reset turn works again.
    segment->device_turn.give(7);
    segment->device_turn.finish();
    segment->device_turn.reset();
    segment->device_turn.give(8);
    CHECK(segment->device_turn.tick() == 8);
  }
}

}  // namespace impetus
