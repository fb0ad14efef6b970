// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link segment (DESIGN.md §2): created by the world manager, opened by the haptic controller.
// Name on the system: "<shm>.world" (see names.h).

#include "common/link/shm/wire_frames.h"
#include "common/link/world_link.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

#include <atomic>
#include <cstdint>
#include <type_traits>

namespace impetus {

static_assert(std::is_trivially_copyable_v<WorldLinkInfo>);

struct WorldLinkLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;

  SegmentHeader header;
  WorldLinkInfo config;  // written once by the world manager before the segment is published; read-only after
  SeqlockChannel<wire::PlaneFrame> planes;       // writer: world manager
  SeqlockChannel<wire::HapticReport> report;     // writer: haptic controller
  SeqlockChannel<LoopStats> world_stats;   // writer: world manager
  SeqlockChannel<LoopStats> haptic_stats;  // writer: haptic controller
  LockstepTurn world_turn;                 // master: haptic controller; follower: world manager
  std::atomic<std::int32_t> haptic_pid{0}; // the attached haptic controller, 0 if none (for the world's liveness checks)
};

}  // namespace impetus
