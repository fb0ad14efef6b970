// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a channel whose writer republishes running state every tick (a haptic report's totals, a device command's
// tensions): the newest frame is what counts, re-reading it is harmless, and a frame that fails decoding is counted
// and the last valid one kept.

#include "common/link/shm/seqlock.h"
#include "common/link/shm/wire_frames.h"

#include <cstdint>

namespace impetus {

template <class Wire, class Frame>
class LatestValid {
 public:
  // The newest valid frame into `out`; false if none was ever valid. Allocation-free.
  bool read(const SeqlockChannel<Wire>& channel, Frame& out) {
    std::uint64_t any = 0;  // the newest frame, new or not
    std::size_t copied = 0;
    if (channel.try_read(wire_, any, 4, &copied)) {
      // The frame's count must not claim more than its writer wrote (a scribbled count).
      if (used_bytes(wire_) <= copied && decode(wire_, frame_) == FrameError::ok) {
        have_ = true;
      } else {
        ++rejected_;
      }
    }
    if (have_) out = frame_;
    return have_;
  }
  std::uint64_t rejected() const { return rejected_; }

 private:
  Wire wire_{};
  Frame frame_{};
  bool have_ = false;
  std::uint64_t rejected_ = 0;
};

}  // namespace impetus
