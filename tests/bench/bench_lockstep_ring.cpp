// SPDX-License-Identifier: Apache-2.0
// The floor under three-process lockstep: the trial's turn-taking (common/runtime/lockstep.h) with no work in it. A
// master (the haptic controller's place) gives a device follower every tick and a world follower every 50th (a 20 Hz
// world), each in its own process, exactly as `--clock lockstep` does. Prints ticks per second, quiet and with one
// core kept busy by another process (the trial's throughput is measured against this; scripts/bench.sh section 5).
// Asserts nothing: timing on a shared VM is a measurement, not a test.
//
//   bench_lockstep_ring [TICKS=300000]

#include "common/runtime/lockstep.h"

#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>

namespace {

using impetus::LockstepTurn;
using impetus::TurnResult;

constexpr std::uint64_t kTicksPerWorldStep = 50;  // a 20 Hz world under a 1 kHz haptic clock

struct Ring {
  LockstepTurn device_turn;
  LockstepTurn world_turn;
};

int follow(LockstepTurn& turn) {
  for (;;) {
    const TurnResult result = turn.wait_turn([] { return getppid() != 1; });
    if (result == TurnResult::shutdown) return 0;
    if (result != TurnResult::ok) return 1;
    turn.finish();
  }
}

pid_t spawn(LockstepTurn& turn) {
  const pid_t pid = fork();
  if (pid == 0) _exit(follow(turn));
  return pid;
}

// Ticks per second of one run of `ticks` ticks; NaN if a follower failed.
double run(Ring& ring, std::uint64_t ticks) {
  new (&ring) Ring();  // fresh turns: no shutdown flag or pending post from the last run
  const pid_t device = spawn(ring.device_turn);
  const pid_t world = spawn(ring.world_turn);
  const auto alive = [](pid_t pid) { return [pid] { return kill(pid, 0) == 0; }; };
  bool ok = true;
  const auto start = std::chrono::steady_clock::now();
  for (std::uint64_t tick = 0; tick < ticks && ok; ++tick) {
    ring.device_turn.give(tick);
    ok = ring.device_turn.wait_done(alive(device), 10.0) == TurnResult::ok;
    if (ok && tick % kTicksPerWorldStep == 0) {
      ring.world_turn.give(tick);
      ok = ring.world_turn.wait_done(alive(world), 10.0) == TurnResult::ok;
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ring.device_turn.request_shutdown();
  ring.world_turn.request_shutdown();
  int status = 0;
  waitpid(device, &status, 0);
  ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  waitpid(world, &status, 0);
  ok = ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  return ok ? static_cast<double>(ticks) / wall_s : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

int main(int argc, char** argv) {
  const long long ticks = argc > 1 ? std::atoll(argv[1]) : 300'000;
  if (argc > 2 || ticks <= 0) {
    std::fprintf(stderr, "usage: bench_lockstep_ring [TICKS>0]\n");
    return 2;
  }
  void* memory = mmap(nullptr, sizeof(Ring), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (memory == MAP_FAILED) {
    std::perror("bench_lockstep_ring: mmap");
    return 1;
  }
  Ring& ring = *new (memory) Ring();

  for (int round = 0; round < 3; ++round) {
    std::printf("lockstep ring, no work, quiet: %.0f ticks/s\n", run(ring, static_cast<std::uint64_t>(ticks)));
    std::fflush(stdout);
  }
  // One core kept busy by a process that never yields: the three processes share the other core with it.
  const pid_t busy = fork();
  if (busy == 0) {
    volatile std::uint64_t spin = 0;
    for (;;) spin = spin + 1;
  }
  for (int round = 0; round < 3; ++round) {
    std::printf("lockstep ring, no work, one core busy: %.0f ticks/s\n",
                run(ring, static_cast<std::uint64_t>(ticks / 10)));
    std::fflush(stdout);
  }
  kill(busy, SIGKILL);
  waitpid(busy, nullptr, 0);
  munmap(memory, sizeof(Ring));
  return 0;
}
