#pragma once
// The world link segment (DESIGN.md §2): created by the world manager, opened by the haptic controller.
// Name on the system: "<shm>.world" (see link_names.h).

#include "common/link/shm/wire_frames.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

#include <atomic>
#include <cstdint>

namespace impetus {

// Written once by the world manager before the segment is published; read-only afterwards.
struct WorldLinkConfig {
  double world_rate_hz = 0.0;
  double world_period_s = 0.0;
  std::uint64_t phase_ticks = 0;  // lockstep: world step i happens at haptic tick i·n + phase_ticks
  ClockMode clock = ClockMode::realtime;
  Coupling coupling = Coupling::impulse;
};

struct WorldLinkLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;

  SegmentHeader header;
  WorldLinkConfig config;
  SeqlockChannel<wire::PlaneFrame> planes;       // writer: world manager
  SeqlockChannel<wire::HapticReport> report;     // writer: haptic controller
  SeqlockChannel<LoopStats> world_stats;   // writer: world manager
  SeqlockChannel<LoopStats> haptic_stats;  // writer: haptic controller
  LockstepTurn world_turn;                 // master: haptic controller; follower: world manager
  std::atomic<std::int32_t> haptic_pid{0}; // the attached haptic controller, 0 if none (for the world's liveness checks)
};

}  // namespace impetus
