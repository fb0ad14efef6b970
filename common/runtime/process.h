// SPDX-License-Identifier: Apache-2.0
#pragma once
// What every node process shares outside its loop: a stop flag raised by SIGINT/SIGTERM, session ids, and whether
// another process still runs.

#include <atomic>
#include <cstdint>

namespace impetus {

// Raised by SIGINT or SIGTERM once install_stop_handlers() ran; loops poll it and finish their current step.
extern std::atomic<bool> g_stop_requested;
void install_stop_handlers();

// A nonzero id that differs between process starts and between calls (random_device, pid and clock mixed): names a
// world, haptic or device session so a peer notices a restart.
std::uint64_t new_session_id();

// Whether process `pid` exists (kill(pid, 0): a syscall, no I/O; cheap enough for a 1 kHz loop's rare checks).
bool process_alive(std::int32_t pid);

}  // namespace impetus
