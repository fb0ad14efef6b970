// SPDX-License-Identifier: Apache-2.0
#pragma once
// When a peer counts as silent (docs/architecture.md §2 "Staleness"): one policy, used by every node and transport.
//
//   a world silent for kWorldStalePeriods world periods  → the haptic side keeps its last planes, no extrapolation;
//   a device silent for kDeviceStale_s                   → the driver commands minimum output;
//   a servo silent for kCommandStale_s                   → the device outputs its minimum (its own watchdog), and
//                                                           the servo, when it runs again, starts a new finger session;
//   an endpoint silent for endpoint_stale_s(T_w)         → the world stops applying its finger;
//   a controlling page silent for kTouchInputStale_s     → the web hand lets go: minimum output, the finger at rest.

#include <algorithm>

namespace impetus {

// Three periods: one late frame is jitter, three in a row is a world that stopped.
inline constexpr double kWorldStalePeriods = 3.0;

// Several host stalls' worth of slack for the device's own 1 kHz loop, and short enough that a dead device does not
// leave the strings pulling for a perceptible time.
inline constexpr double kDeviceStale_s = 0.05;

// The other direction, as an amplifier's watchdog: a servo that has sent no new command for this long is not in
// control, so the device stops applying its last one. The same slack as kDeviceStale_s: 50 ticks of the 1 kHz servo.
inline constexpr double kCommandStale_s = 0.05;

// The page sends its pointer at least every 10 ms (viewer/web/touch.js). 40 ms of silence, four messages missed in a
// row, is a page gone without a word (a lost connection): the hand lets go on the next tick, within the 50 ms a
// device gets (kDeviceStale_s). A page that closes or hides says so, and the hand lets go at once.
inline constexpr double kTouchInputStale_s = 0.04;

// Three world periods without a report, and at least 100 ms (several host stalls), is a haptic side gone.
inline constexpr double kEndpointStaleMin_s = 0.1;
inline double endpoint_stale_s(double world_period_s) {
  return std::max(kWorldStalePeriods * world_period_s, kEndpointStaleMin_s);
}

inline bool world_stale(double frame_age_s, double world_period_s) {
  return frame_age_s > kWorldStalePeriods * world_period_s;
}

inline bool device_stale(double state_age_s) { return state_age_s > kDeviceStale_s; }

inline bool command_stale(double command_age_s) { return command_age_s > kCommandStale_s; }

}  // namespace impetus
