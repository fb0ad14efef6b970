// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world view segment (docs/architecture.md §1, §2): created by the world manager beside its world link, opened
// read-only by any number of viewers. Name on the system: "<shm>.view" (see names.h).

#include "common/contract/world_view.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

namespace impetus {

struct WorldViewLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_view;

  SegmentHeader header;
  SeqlockChannel<ViewScene> scene;         // writer: world manager, once at start
  SeqlockChannel<WorldSnapshot> snapshot;  // writer: world manager, every step (only the used prefix is written)
};

}  // namespace impetus
