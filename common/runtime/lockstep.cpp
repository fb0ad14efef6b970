#include "common/runtime/lockstep.h"

#include <time.h>

#include <cerrno>

namespace impetus {
namespace {

// How often a waiter wakes to check its peer and the shutdown flag: short enough that a dead peer is noticed quickly,
// long enough that idle waiting costs nothing measurable.
constexpr long kWaitSliceNs = 100'000'000;
constexpr std::int64_t kSpinNs = 50'000;

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

const char* to_string(ClockMode mode) { return mode == ClockMode::lockstep ? "lockstep" : "realtime"; }

LockstepTurn::LockstepTurn() {
  sem_init(&go_, /*pshared=*/1, 0);
  sem_init(&done_, /*pshared=*/1, 0);
}

void LockstepTurn::reset() {
  sem_destroy(&go_);
  sem_destroy(&done_);
  sem_init(&go_, 1, 0);
  sem_init(&done_, 1, 0);
}

void LockstepTurn::give(std::uint64_t tick) {
  tick_.store(tick, std::memory_order_release);
  sem_post(&go_);
}

void LockstepTurn::finish() { sem_post(&done_); }

void LockstepTurn::request_shutdown() {
  shutdown_.store(1, std::memory_order_release);
  sem_post(&go_);  // wake a follower that is waiting for a turn
}

LockstepTurn::Wait LockstepTurn::wait_slice(sem_t& semaphore) {
  // A peer's turn is usually a few microseconds of work on the other core, while waking a thread blocked in the kernel
  // costs tens of microseconds on this VM: poll briefly first, then block. The poll is bounded (kSpinNs) so a long
  // turn (a world step of a big scene) or a machine shared by more processes wastes at most that much per wait.
  const std::int64_t spin_until_ns = monotonic_ns() + kSpinNs;
  do {
    if (sem_trywait(&semaphore) == 0) return Wait::posted;
    cpu_relax();
  } while (monotonic_ns() < spin_until_ns);
  timespec deadline{};
  clock_gettime(CLOCK_MONOTONIC, &deadline);
  deadline.tv_nsec += kWaitSliceNs;
  if (deadline.tv_nsec >= 1'000'000'000) {
    deadline.tv_sec += 1;
    deadline.tv_nsec -= 1'000'000'000;
  }
  for (;;) {
    if (sem_clockwait(&semaphore, CLOCK_MONOTONIC, &deadline) == 0) return Wait::posted;
    if (errno == EINTR) continue;
    return errno == ETIMEDOUT ? Wait::slice_over : Wait::error;
  }
}

}  // namespace impetus
