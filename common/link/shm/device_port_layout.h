// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device port segment (docs/architecture.md §2): created by the haptic controller, opened by a device (spidar_sim).
// Name on the system: "<shm>.device" (see names.h).
//
// Attach protocol: a device claims the port by swapping device_pid from 0 to its pid, then follows the haptic
// controller (lockstep: waits for turns; real time: publishes states at its own rate). To detach it sets
// `detaching` and, in lockstep, answers one last turn without a new state; the haptic controller then frees the slot.
// A device that dies is noticed by the haptic controller (pid gone), which resets the turn and frees the slot.

#include "common/link/shm/wire_frames.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

#include <array>
#include <atomic>
#include <cstdint>

namespace impetus {

struct DevicePortLayout {
  static constexpr SegmentKind kKind = SegmentKind::device_port;

  SegmentHeader header;
  ClockMode clock = ClockMode::realtime;    // set by the haptic controller at creation
  std::uint32_t reserved = 0;
  double haptic_period_s = 0.0;             // the device's tick in lockstep
  std::uint64_t device_hash = 0;            // DeviceDescription::hash of the host's device
  std::array<char, 256> device_source{};    // and where it came from, NUL-terminated (truncated if longer)
  SeqlockChannel<wire::DeviceCommand> command;    // writer: haptic controller
  SeqlockChannel<wire::DeviceState> state;        // writer: device
  SeqlockChannel<LoopStats> device_stats;   // writer: device
  LockstepTurn device_turn;                 // master: haptic controller; follower: device
  std::atomic<std::int32_t> device_pid{0};  // 0 = free
  std::atomic<std::uint32_t> detaching{0};  // set by the device before its last turn
};

}  // namespace impetus
