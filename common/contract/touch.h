// SPDX-License-Identifier: Apache-2.0
#pragma once
// What crosses the touch port (docs/architecture.md §1.2 "The web hand"): a person's pointer on the viewer's page
// steering a simulated hand in the haptic controller. The viewer writes TouchInput, the web hand device writes
// HandState. World frame, z up, SI units; times are CLOCK_MONOTONIC nanoseconds, which both processes share on one
// host.

#include "common/contract/vec3.h"

#include <cmath>
#include <cstdint>
#include <type_traits>

namespace impetus {

// The controlling page's latest wish, as the viewer received it.
struct TouchInput {
  std::uint64_t page = 0;          // serial of the controlling page; 0: no page holds control
  std::int64_t received_ns = 0;    // when the viewer received the page's latest message (its heartbeat)
  std::int64_t released_ns = 0;    // when the page let go (closed, hidden, released); 0 while it holds
  Vec3 target_m{};                 // where the person points the finger
};
static_assert(std::is_trivially_copyable_v<TouchInput>);

// The simulated hand as the device last stepped it, for the page to start from and to draw the workspace.
struct HandState {
  std::int64_t heartbeat_ns = 0;   // the device tick that wrote it
  Vec3 finger_m{};                 // the simulated fingertip
  Vec3 workspace_min_m{};          // where a target may go: the device clamps to this box
  Vec3 workspace_max_m{};
  std::uint64_t page = 0;          // the page whose input it follows; 0: resting, no hand on it
  double max_force_N = 0.0;        // the largest force the device renders
};
static_assert(std::is_trivially_copyable_v<HandState>);

// Whether a received input is usable: finite target within `bound_m` of the origin and sane times. A reader drops
// (and counts) anything else, whatever wrote it.
inline bool touch_input_valid(const TouchInput& input, double bound_m) {
  for (double value : input.target_m) {
    if (!std::isfinite(value) || std::abs(value) > bound_m) return false;
  }
  return input.received_ns >= 0 && input.released_ns >= 0;
}

}  // namespace impetus
