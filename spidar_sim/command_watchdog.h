// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device's watchdog on the servo → device direction (common/runtime/staleness.h), as a motor amplifier has one: a
// command is applied while new ones keep coming; once none has come for kCommandStale_s of device time the device
// outputs its minimum until a new one comes. A stalled servo therefore cannot leave the last force on the hand.
// Device time: in lockstep every tick brings a command, so a lockstep run is never affected. No allocation.

#include "common/contract/frames.h"
#include "common/runtime/staleness.h"

#include <cstdint>

namespace impetus {

class CommandWatchdog {
 public:
  // Whether `command` (nullptr: none has ever come) may be applied at device time `now_s`.
  bool applies(const DeviceCommand* command, double now_s) {
    if (command == nullptr) return false;
    if (!seen_ || command->tick != last_tick_ || command->haptic_session != last_session_) {
      seen_ = true;
      last_tick_ = command->tick;
      last_session_ = command->haptic_session;
      last_new_s_ = now_s;
    }
    const bool fresh = !command_stale(now_s - last_new_s_);
    if (!fresh) ++stale_ticks_;
    return fresh;
  }
  // Device ticks spent at minimum output because the last command had gone stale.
  std::uint64_t stale_ticks() const { return stale_ticks_; }

 private:
  bool seen_ = false;
  std::uint64_t last_tick_ = 0;
  std::uint64_t last_session_ = 0;
  double last_new_s_ = 0.0;
  std::uint64_t stale_ticks_ = 0;
};

}  // namespace impetus
