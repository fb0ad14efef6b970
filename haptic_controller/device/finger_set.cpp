// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/finger_set.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace impetus {

FingerSet::FingerSet(std::span<HapticDevice* const> fingers) {
  if (fingers.empty() || fingers.size() > kMaxFingers) {
    throw std::invalid_argument("a device has 1 to " + std::to_string(kMaxFingers) + " fingers, not " +
                                std::to_string(fingers.size()));
  }
  count_ = static_cast<std::uint32_t>(fingers.size());
  limits_.max_force_N = fingers[0]->limits().max_force_N;
  for (std::uint32_t k = 0; k < count_; ++k) {
    if (fingers[k] == nullptr || fingers[k]->finger_count() != 1) {
      throw std::invalid_argument("finger " + std::to_string(k) + " of a finger set must be a one-finger device");
    }
    fingers_[k] = fingers[k];
    limits_.max_force_N = std::min(limits_.max_force_N, fingers[k]->limits().max_force_N);
  }
}

bool FingerSet::wait_attached() {
  for (std::uint32_t k = 0; k < count_; ++k) {
    if (!fingers_[k]->wait_attached()) return false;
  }
  return true;
}

const FingerSample* FingerSet::read(std::uint64_t tick, double now_s) {
  bool any = false;
  for (std::uint32_t k = 0; k < count_; ++k) {
    const FingerSample* sample = fingers_[k]->read(tick, now_s);
    samples_[k] = sample != nullptr ? *sample : FingerSample{};
    samples_[k].present = sample != nullptr;
    any = any || sample != nullptr;
  }
  return any ? samples_.data() : nullptr;
}

bool FingerSet::command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) {
  std::array<FingerCommand, kMaxFingers> commands{};
  commands[0].force_N = force_N;
  commands[0].render = render;
  return (command_fingers(tick, commands.data()) & 1u) == 0;
}

std::uint32_t FingerSet::command_fingers(std::uint64_t tick, const FingerCommand* commands) {
  std::uint32_t saturated = 0;
  for (std::uint32_t k = 0; k < count_; ++k) {
    if (!fingers_[k]->command(tick, commands[k].force_N, commands[k].render)) saturated |= 1u << k;
  }
  return saturated;
}

void FingerSet::note_world(bool present) {
  for (std::uint32_t k = 0; k < count_; ++k) fingers_[k]->note_world(present);
}

void FingerSet::end_session() {
  for (std::uint32_t k = 0; k < count_; ++k) fingers_[k]->end_session();
}

DeviceCounters FingerSet::counters() const {
  DeviceCounters total;
  for (std::uint32_t k = 0; k < count_; ++k) {
    const DeviceCounters counters = fingers_[k]->counters();
    total.saturations += counters.saturations;
    total.rejected_frames += counters.rejected_frames;
    total.devices_lost += counters.devices_lost;
    total.channel_repairs += counters.channel_repairs;
  }
  return total;
}

}  // namespace impetus
