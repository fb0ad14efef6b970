// SPDX-License-Identifier: Apache-2.0
#pragma once
// The touch port segment (docs/architecture.md §2): created by the web hand device in the haptic controller, opened by
// the viewer that serves the controlling page. Name on the system: "<shm>.touch" (see names.h).

#include "common/contract/touch.h"
#include "common/link/shm/segment.h"
#include "common/link/shm/seqlock.h"

namespace impetus {

struct TouchPortLayout {
  static constexpr SegmentKind kKind = SegmentKind::touch_port;

  SegmentHeader header;
  SeqlockChannel<TouchInput> input;  // writer: the viewer
  SeqlockChannel<HandState> hand;    // writer: the web hand device, every tick
};

}  // namespace impetus
