// SPDX-License-Identifier: Apache-2.0
#pragma once
// The touch port over shared memory (touch_port_layout.h): the device creates "<shm>.touch", the viewer opens it.

#include "common/link/shm/touch_port_layout.h"
#include "common/link/touch_port.h"

#include <string>

namespace impetus {

class ShmTouchPortHost final : public TouchPortHost {
 public:
  // Creates "<shm>.touch"; throws SegmentError if a live process owns it.
  explicit ShmTouchPortHost(const std::string& shm);

  bool latest_input(TouchInput& out) override;
  void publish_hand(const HandState& hand) override { segment_->hand.write(hand); }
  std::uint64_t rejected_inputs() const override { return rejected_; }
  const std::string& name() const { return segment_.name(); }

 private:
  Segment<TouchPortLayout> segment_;
  std::uint64_t last_sequence_ = 0;
  TouchInput input_{};
  bool have_input_ = false;
  std::uint64_t rejected_ = 0;
};

class ShmTouchPortClient final : public TouchPortClient {
 public:
  // Opens "<shm>.touch"; throws SegmentError if it is missing (no web hand device runs there) or not a touch port.
  explicit ShmTouchPortClient(const std::string& shm);

  void publish_input(const TouchInput& input) override { segment_->input.write(input); }
  bool latest_hand(HandState& out) override;
  bool host_alive() const override { return segment_.creator_alive(); }

 private:
  Segment<TouchPortLayout> segment_;
  std::uint64_t last_sequence_ = 0;
  HandState hand_{};
  bool have_hand_ = false;
};

}  // namespace impetus
