// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link segment (docs/architecture.md §2): created by the world manager, opened by the haptic controller.
// Name on the system: "<shm>.world" (see names.h).

#include "common/link/shm/wire_frames.h"
#include "common/link/world_link.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace impetus {

static_assert(std::is_trivially_copyable_v<WorldLinkInfo>);

// One endpoint's channels. A haptic controller takes a slot for each of its endpoints by swapping owner_pid from 0
// (or from a pid that is no longer alive) to its own; only the holder writes its report and stats channels.
struct EndpointSlotLayout {
  SeqlockChannel<wire::PlaneFrame> planes;      // writer: world manager
  SeqlockChannel<wire::HapticReport> report;    // writer: the slot's holder
  SeqlockChannel<LoopStats> haptic_stats;       // writer: the slot's holder
  std::atomic<std::int32_t> owner_pid{0};       // the holder, 0 if none
  // Lockstep, a second (third, ...) controller: its first slot is marked and carries its turn. The master gives it
  // a turn every tick, after its own and before the world's.
  std::atomic<std::uint32_t> follower{0};       // 1: the holder follows the master's ticks through follower_turn
  LockstepTurn follower_turn;                   // master: the lockstep master; follower: the holder
};

struct WorldLinkLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;

  SegmentHeader header;
  WorldLinkInfo config;  // written once by the world manager before the segment is published; read-only after
  SeqlockChannel<LoopStats> world_stats;   // writer: world manager
  std::array<EndpointSlotLayout, kMaxEndpoints> slots;
  LockstepTurn world_turn;                 // master: the lockstep haptic controller; follower: world manager
  // The lockstep master, 0 if none (the world's liveness check while it waits for a turn; a second lockstep
  // controller follows it).
  std::atomic<std::int32_t> master_pid{0};
};

}  // namespace impetus
