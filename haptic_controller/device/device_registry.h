// SPDX-License-Identifier: Apache-2.0
#pragma once
// The haptic devices a user can choose by name (haptic_controller --device NAME[:ARGUMENT], the in-process loop and
// Python), in one table (docs/architecture.md §7): each entry's name, what its argument is, and how it is built. The
// daemons, the loop and Python assemble a device only through here.
//
// A device serves one or more fingers, each on its own device port (a SPIDAR with a string set per finger); the ports
// carry the device's description so both ends agree on the hardware (common/link/device_port.h).

#include "common/link/device_port.h"
#include "common/runtime/lockstep.h"
#include "haptic_controller/device/finger_set.h"
#include "haptic_controller/device/haptic_device.h"

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace impetus {

// A device as chosen: it describes itself to its ports and builds the driver of one finger on a port.
class DeviceType {
 public:
  virtual ~DeviceType() = default;
  // What each of its ports carries, checked by the device at the other end.
  virtual const DeviceDescription& description() const = 0;
  // One finger's driver on `port`, which must outlive it; `haptic_session` stamps the commands.
  virtual std::unique_ptr<HapticDevice> make_finger(DevicePortHost& port, ClockMode clock,
                                                    std::uint64_t haptic_session) const = 0;
  // Whether its fingers are reached through device ports, a device process at the other end (spidar_sim, a real
  // SPIDAR's bridge). One that is not (the web hand, simulated in the haptic controller) is built by make_local.
  virtual bool uses_device_ports() const { return true; }
  // The whole device, in this process, with whatever it opens under `shm` (names.h); for a type without device
  // ports. Throws std::invalid_argument for a clock it cannot run on.
  virtual std::unique_ptr<HapticDevice> make_local(const std::string& shm, ClockMode clock) const;
};

struct DeviceEntry {
  std::string_view name;
  std::string_view argument;  // what may follow "NAME:", for --help and errors ("" if nothing may)
  // Builds the type from the argument ("" when none was given); throws std::runtime_error naming the file and field.
  std::unique_ptr<DeviceType> (*parse)(const std::string& argument);
};

// The device `spec` names ("NAME" or "NAME:ARGUMENT"); throws std::invalid_argument for an unknown name, listing the
// known ones with their arguments.
std::unique_ptr<DeviceType> parse_device(const std::string& spec);
// "spidar or spidar:FILE.json": every entry's forms, for --help and errors.
std::string device_forms();

// A device of one or more fingers assembled from its type: a driver per port, served to the haptic node as one
// (a FingerSet for several). Owns the drivers; the ports must outlive it.
class AssembledDevice {
 public:
  AssembledDevice(const DeviceType& type, std::span<DevicePortHost* const> ports, ClockMode clock,
                  std::uint64_t haptic_session);
  // A type without device ports (DeviceType::make_local).
  AssembledDevice(const DeviceType& type, const std::string& shm, ClockMode clock);
  HapticDevice& device() { return set_ ? static_cast<HapticDevice&>(*set_) : *fingers_.front(); }

 private:
  std::vector<std::unique_ptr<HapticDevice>> fingers_;
  std::optional<FingerSet> set_;
};

}  // namespace impetus
