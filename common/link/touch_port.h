// SPDX-License-Identifier: Apache-2.0
#pragma once
// The touch port (docs/architecture.md §2): the viewer's page steering the web hand device, both on one machine. The
// host end belongs to the device (haptic_controller --device web), the client end to the viewer. Transports validate
// what they read, so each end sees only usable frames (common/contract/touch.h).

#include "common/contract/touch.h"

#include <cstdint>

namespace impetus {

// The device's end. Used from the servo thread: no call allocates, locks or blocks.
class TouchPortHost {
 public:
  virtual ~TouchPortHost() = default;
  // The newest usable input (whether or not it is new since the last call); false if none was ever written.
  virtual bool latest_input(TouchInput& out) = 0;
  virtual void publish_hand(const HandState& hand) = 0;
  // Inputs dropped as unusable (non-finite, out of range).
  virtual std::uint64_t rejected_inputs() const = 0;
};

// The viewer's end.
class TouchPortClient {
 public:
  virtual ~TouchPortClient() = default;
  virtual void publish_input(const TouchInput& input) = 0;
  // The hand's newest state; false if the device has written none.
  virtual bool latest_hand(HandState& out) = 0;
  // False once the device has gone (exited, died): the client opens the port again to reach its successor.
  virtual bool host_alive() const { return true; }
};

// Bound on a target's coordinates (m) that any reader accepts: a room. Devices clamp to their own, smaller workspace.
inline constexpr double kMaxTouchTarget_m = 10.0;

}  // namespace impetus
