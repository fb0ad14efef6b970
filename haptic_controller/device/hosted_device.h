// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device as the haptic controller daemon hosts it (docs/architecture.md §1.2, §2): for a device behind device
// ports, one shared-memory port per finger under `--shm NAME` and a driver on each; for a device in this process (the
// web hand), the device itself. Owns what it opens; the ports' names go when it does.

#include "common/link/shm/shm_device_port.h"
#include "haptic_controller/device/device_registry.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace impetus {

class HostedDevice {
 public:
  // `fingers` ports (or one device in this process) for `type`, named from `shm`; the servo ticks every
  // `haptic_period_s`. Throws std::invalid_argument for several fingers on a one-finger device or a clock the device
  // cannot run on, SegmentError if a live process owns a port.
  HostedDevice(const DeviceType& type, const std::string& spec, const std::string& shm, ClockMode clock,
               double haptic_period_s, std::uint64_t haptic_session, unsigned fingers);

  HapticDevice& device() { return device_->device(); }
  // Where a device reaches it, for the start-up line: the port names, or the touch port.
  const std::string& where() const { return where_; }

 private:
  std::vector<std::unique_ptr<ShmDevicePortHost>> ports_;
  std::optional<AssembledDevice> device_;
  std::string where_;
};

}  // namespace impetus
