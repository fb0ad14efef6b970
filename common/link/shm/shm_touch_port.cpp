// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/shm_touch_port.h"

#include "common/link/shm/names.h"

namespace impetus {

ShmTouchPortHost::ShmTouchPortHost(const std::string& shm)
    : segment_(Segment<TouchPortLayout>::create(touch_port_name(shm))) {}

bool ShmTouchPortHost::latest_input(TouchInput& out) {
  TouchInput fresh{};
  if (segment_->input.try_read(fresh, last_sequence_)) {
    if (touch_input_valid(fresh, kMaxTouchTarget_m)) {
      input_ = fresh;
      have_input_ = true;
    } else {
      ++rejected_;
    }
  }
  if (have_input_) out = input_;
  return have_input_;
}

ShmTouchPortClient::ShmTouchPortClient(const std::string& shm)
    : segment_(Segment<TouchPortLayout>::open(touch_port_name(shm))) {}

bool ShmTouchPortClient::latest_hand(HandState& out) {
  HandState fresh{};
  if (segment_->hand.try_read(fresh, last_sequence_)) {
    hand_ = fresh;
    have_hand_ = true;
  }
  if (have_hand_) out = hand_;
  return have_hand_;
}

}  // namespace impetus
