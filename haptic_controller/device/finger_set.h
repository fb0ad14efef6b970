// SPDX-License-Identifier: Apache-2.0
#pragma once
// Several one-finger devices as one device of several fingers (docs/architecture.md §1.2): a SPIDAR with a string set
// per finger is a SpidarDriver per finger, each on its own device port. Finger k of the set is device k.
//
// Lockstep: read() gives each finger's device its turn in finger order, so a tick is one deterministic sequence.
// Real time: each finger's newest reading; a finger whose device is absent or stale is marked not present (its servo
// gets no finger), and read() returns nullptr only when every finger is absent. The limits are the smallest of the
// fingers'. Allocation-free after construction.

#include "haptic_controller/device/haptic_device.h"

#include <array>
#include <span>

namespace impetus {

class FingerSet final : public HapticDevice {
 public:
  // `fingers` (1 to kMaxFingers, each a one-finger device) must outlive the set. Throws std::invalid_argument
  // otherwise.
  explicit FingerSet(std::span<HapticDevice* const> fingers);

  const DeviceLimits& limits() const override { return limits_; }
  std::uint32_t finger_count() const override { return count_; }
  bool wait_attached() override;
  const FingerSample* read(std::uint64_t tick, double now_s) override;
  bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) override;
  void note_world(bool present) override;
  std::uint32_t command_fingers(std::uint64_t tick, const FingerCommand* commands) override;
  void end_session() override;
  DeviceCounters counters() const override;

 private:
  std::array<HapticDevice*, kMaxFingers> fingers_{};
  std::uint32_t count_ = 0;
  DeviceLimits limits_;
  std::array<FingerSample, kMaxFingers> samples_{};
};

}  // namespace impetus
