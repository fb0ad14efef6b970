// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/lockstep.h"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace impetus {
namespace {

// How often a waiter wakes to check its peer and the shutdown flag: short enough that a dead peer is noticed quickly,
// long enough that idle waiting costs nothing measurable.
constexpr long kWaitSliceNs = 100'000'000;
// A waiter polls before it blocks, for at most kMaxSpinNs: a peer's turn is usually a few microseconds of work on the
// other core, while waking a thread blocked in the kernel costs tens of microseconds on this VM.
constexpr std::int64_t kMaxSpinNs = 50'000;
constexpr std::int64_t kMinSpinNs = 1'000;

// How long this thread polls: twice the waits it has seen lately, within [kMinSpinNs, kMaxSpinNs]. When the peer runs
// on a free core its turns come within a few microseconds and the poll catches them. When the cores are busy (another
// program, or more processes than cores) the peer cannot run while we poll, turns take a scheduler slice, and the
// poll shrinks towards kMinSpinNs instead of burning 50 µs of the peer's CPU on every turn. Per thread: each process's
// waiter adapts to what it waits for.
thread_local std::int64_t t_spin_ns = kMaxSpinNs;

// This thread's idle work (LockstepIdleWork), if any.
thread_local LockstepIdleWork::Work t_idle_work = nullptr;
thread_local void* t_idle_context = nullptr;

bool do_idle_work() { return t_idle_work != nullptr && t_idle_work(t_idle_context); }

void learn_wait(std::int64_t waited_ns) {
  if (waited_ns < kMaxSpinNs / 2) {
    t_spin_ns = std::clamp<std::int64_t>(2 * waited_ns, kMinSpinNs, kMaxSpinNs);  // a poll this long would catch it
  } else {
    t_spin_ns = std::max(kMinSpinNs, t_spin_ns / 2);  // polling would not have helped: poll less
  }
}

std::int64_t monotonic_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

LockstepIdleWork::LockstepIdleWork(Work work, void* context) {
  t_idle_work = work;
  t_idle_context = context;
}

LockstepIdleWork::~LockstepIdleWork() {
  t_idle_work = nullptr;
  t_idle_context = nullptr;
}

const char* to_string(ClockMode mode) { return mode == ClockMode::lockstep ? "lockstep" : "realtime"; }

const char* to_string(TurnResult result) {
  switch (result) {
    case TurnResult::ok: return "ok";
    case TurnResult::shutdown: return "the session ended";
    case TurnResult::peer_gone: return "the peer went away";
    case TurnResult::timed_out: return "the peer stopped answering";
    case TurnResult::corrupted: return "the lockstep turn in shared memory holds values the protocol never writes "
                                       "(corrupted by another process)";
  }
  return "unknown";
}

void LockstepTurn::reset() {
  go_.store(kIdle, std::memory_order_release);
  done_.store(kIdle, std::memory_order_release);
}

void LockstepTurn::give(std::uint64_t tick) {
  tick_.store(tick, std::memory_order_release);
  post(go_);
}

void LockstepTurn::finish() { post(done_); }

void LockstepTurn::request_shutdown() {
  shutdown_.store(1, std::memory_order_release);
  post(go_);  // wake a follower that is waiting for a turn
}

void LockstepTurn::post(std::atomic<std::uint32_t>& turn) {
  // Only a waiter that said it sleeps (kAsleep) needs the kernel: one still polling sees the post by itself, and a
  // futex wake costs a system call (with a page-table walk for a process-shared word) on every turn otherwise.
  if (turn.exchange(kPosted, std::memory_order_acq_rel) == kAsleep) {
    // Process-shared futex (no FUTEX_PRIVATE_FLAG): the waiter is in another process. Waking nobody is harmless.
    syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&turn), FUTEX_WAKE, 1, nullptr, nullptr, 0);
  }
}

LockstepTurn::Wait LockstepTurn::wait_slice(std::atomic<std::uint32_t>& turn) {
  // Takes the pending turn (posted → idle). Any value but the three states was not written by the protocol.
  const auto take = [&turn]() -> int {
    std::uint32_t expected = kPosted;
    if (turn.compare_exchange_strong(expected, kIdle, std::memory_order_acq_rel)) return 1;
    return expected == kIdle || expected == kAsleep ? 0 : -1;
  };
  // Poll briefly first (t_spin_ns, adapted to the waits seen), then block; while there is idle work, do it between
  // polls and do not block.
  const std::int64_t start_ns = monotonic_ns();
  const std::int64_t spin_until_ns = start_ns + t_spin_ns;
  std::int64_t now_ns = start_ns;
  bool worked = false;
  do {
    const int taken = take();
    if (taken != 0) {
      learn_wait(now_ns - start_ns);
      return taken > 0 ? Wait::posted : Wait::corrupted;
    }
    worked = do_idle_work();
    if (!worked) cpu_relax();
    now_ns = monotonic_ns();
  } while (worked || now_ns < spin_until_ns);
  const std::int64_t deadline_ns = monotonic_ns() + kWaitSliceNs;
  for (;;) {
    const int taken = take();
    if (taken != 0) {
      learn_wait(monotonic_ns() - start_ns);
      return taken > 0 ? Wait::posted : Wait::corrupted;
    }
    const std::int64_t left_ns = deadline_ns - monotonic_ns();
    if (left_ns <= 0) return Wait::slice_over;
    // Say we sleep (idle → asleep) so the next post wakes us; a post that came first fails the exchange and is taken
    // above on the next pass.
    std::uint32_t expected = kIdle;
    if (!turn.compare_exchange_strong(expected, kAsleep, std::memory_order_acq_rel) && expected != kAsleep) continue;
    const timespec timeout{static_cast<time_t>(left_ns / 1'000'000'000), static_cast<long>(left_ns % 1'000'000'000)};
    // Sleeps only while the word still says asleep; returns at a post, a signal or the timeout, each re-checked above.
    if (syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&turn), FUTEX_WAIT, kAsleep, &timeout, nullptr, 0) != 0 &&
        errno != EAGAIN && errno != EINTR && errno != ETIMEDOUT) {
      return Wait::corrupted;  // the kernel refused the word itself (it cannot, unless the mapping is gone)
    }
  }
}

}  // namespace impetus
