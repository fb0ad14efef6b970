// SPDX-License-Identifier: Apache-2.0
#pragma once
// Turn-taking for `--clock lockstep` (docs/architecture.md §3): the haptic controller's tick count is the master clock;
// the device advances once per haptic tick and the world steps at tick i·n + phase. A follower sleeps on an
// interprocess semaphore until the master gives it a turn, does its step, and hands the turn back — no long spinning
// (the machine has 2 cores) and the order of every read and write is fixed, so runs are bitwise reproducible.
//
// Every wait is sliced (kWaitSlice) so a waiter notices a dead peer or a shutdown request instead of hanging forever.

#include <atomic>
#include <cstdint>

namespace impetus {

enum class ClockMode : std::uint32_t { realtime = 0, lockstep = 1 };
const char* to_string(ClockMode mode);

// `corrupted`: a word of the turn holds a value the protocol never writes (another process scribbled on the segment).
enum class TurnResult { ok, shutdown, peer_gone, timed_out, corrupted };
// What a TurnResult means, for messages.
const char* to_string(TurnResult result);

// Lives in a segment; every word is a process-shared atomic. A turn is handed over by a binary semaphore built on a
// futex word (idle, posted, or idle with the waiter asleep in the kernel: only then does a post make a system call)
// rather than a POSIX sem_t: glibc aborts the whole process when a scribbled sem_t makes the futex call fail, whereas
// here every word is checked before use and a value the protocol never writes ends the wait with `corrupted`, so the
// caller can say so and stop cleanly.
class LockstepTurn {
 public:
  LockstepTurn() = default;
  // Clears both turns. Only when no process can be waiting on them (the peer died and its slot is not yet released),
  // so a stale post from a dead peer cannot hand a new peer a turn that was never given.
  void reset();

  // Master: hands tick `tick` to the follower.
  void give(std::uint64_t tick);
  // Master: waits for the follower to finish its turn. `peer_alive()` is polled every slice; the wait gives up after
  // `timeout_s` (a follower that is alive but stuck for that long is a bug worth stopping for).
  template <class PeerAlive>
  TurnResult wait_done(PeerAlive&& peer_alive, double timeout_s);

  // Follower: waits for a turn; on ok, `tick()` is the tick to do. `keep_waiting()` is polled every slice.
  template <class KeepWaiting>
  TurnResult wait_turn(KeepWaiting&& keep_waiting);
  // Follower: hands the turn back.
  void finish();

  std::uint64_t tick() const { return tick_.load(std::memory_order_acquire); }
  // Master: ends the session; a follower's wait returns `shutdown` from then on.
  void request_shutdown();
  bool shutdown_requested() const { return shutdown_.load(std::memory_order_acquire) == 1; }

 private:
  enum class Wait { posted, slice_over, corrupted };
  // The states of a turn word. Idle: no turn pending, the waiter (if any) polls. Posted: a turn is pending. Asleep:
  // no turn pending and the waiter blocks in the kernel, so the poster must wake it.
  static constexpr std::uint32_t kIdle = 0;
  static constexpr std::uint32_t kPosted = 1;
  static constexpr std::uint32_t kAsleep = 2;
  static Wait wait_slice(std::atomic<std::uint32_t>& turn);
  static void post(std::atomic<std::uint32_t>& turn);
  bool shutdown_corrupted() const { return shutdown_.load(std::memory_order_acquire) > 1; }

  std::atomic<std::uint32_t> go_{kIdle};    // master → follower
  std::atomic<std::uint32_t> done_{kIdle};  // follower → master
  std::atomic<std::uint64_t> tick_{0};
  std::atomic<std::uint32_t> shutdown_{0};
};
static_assert(std::atomic<std::uint32_t>::is_always_lock_free);

// Work a lockstep process does while it waits for a turn, instead of only polling: formatting its logs' rows
// (rt_log.h drain_one), so they are written in time it would otherwise spend waiting. `work(context)` does a little
// (microseconds: one row) and returns whether it did anything; the waiter polls its turn between calls, so the turn is
// taken at most one call late. Installed for the calling thread while the guard lives (one at a time).
class LockstepIdleWork {
 public:
  using Work = bool (*)(void* context);
  LockstepIdleWork(Work work, void* context);
  ~LockstepIdleWork();
  LockstepIdleWork(const LockstepIdleWork&) = delete;
  LockstepIdleWork& operator=(const LockstepIdleWork&) = delete;
};

template <class PeerAlive>
TurnResult LockstepTurn::wait_done(PeerAlive&& peer_alive, double timeout_s) {
  const int slices = static_cast<int>(timeout_s / 0.1) + 1;
  for (int slice = 0; slice < slices; ++slice) {
    switch (wait_slice(done_)) {
      case Wait::posted: return TurnResult::ok;
      case Wait::corrupted: return TurnResult::corrupted;
      case Wait::slice_over:
        if (!peer_alive()) return TurnResult::peer_gone;
        break;
    }
  }
  return TurnResult::timed_out;
}

template <class KeepWaiting>
TurnResult LockstepTurn::wait_turn(KeepWaiting&& keep_waiting) {
  for (;;) {
    if (shutdown_corrupted()) return TurnResult::corrupted;
    if (shutdown_requested()) return TurnResult::shutdown;
    switch (wait_slice(go_)) {
      case Wait::posted:
        if (shutdown_corrupted()) return TurnResult::corrupted;
        return shutdown_requested() ? TurnResult::shutdown : TurnResult::ok;
      case Wait::corrupted: return TurnResult::corrupted;
      case Wait::slice_over:
        if (!keep_waiting()) return TurnResult::peer_gone;
        break;
    }
  }
}

}  // namespace impetus
