// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/hosted_device.h"

#include "common/link/shm/names.h"

#include <stdexcept>

namespace impetus {

HostedDevice::HostedDevice(const DeviceType& type, const std::string& spec, const std::string& shm, ClockMode clock,
                           double haptic_period_s, std::uint64_t haptic_session, unsigned fingers) {
  if (!type.uses_device_ports()) {
    if (fingers != 1) {
      throw std::invalid_argument("--device " + spec + " has one finger, not --fingers " + std::to_string(fingers));
    }
    device_.emplace(type, shm, clock);
    where_ = type.description().source + ", touch port '" + touch_port_name(shm) + "' (viewer --shm " + shm +
             " --touch)";
    return;
  }
  std::vector<DevicePortHost*> ports;
  for (unsigned k = 0; k < fingers; ++k) {
    ports_.push_back(std::make_unique<ShmDevicePortHost>(shm, clock, haptic_period_s, type.description(), k));
    ports.push_back(ports_.back().get());
  }
  device_.emplace(type, ports, clock, haptic_session);
  where_ = "device port '" + ports_[0]->name() + "'" +
           (fingers > 1 ? " and " + std::to_string(fingers - 1) + " more, one per finger" : "");
}

}  // namespace impetus
