// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/device_registry.h"

#include "common/runtime/message_text.h"
#include "common/spidar/geometry.h"
#include "common/spidar/grip_geometry.h"
#include "common/link/shm/shm_touch_port.h"
#include "haptic_controller/device/grip_port_driver.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/device/web_hand.h"

#include <stdexcept>

namespace impetus {
namespace {

// A device a file describes (or the built-in geometry, without one): its geometry, its content hash and its source
// are its description, and each finger is a `Driver` over that geometry.
template <typename Device, typename Driver>
class FileDeviceType final : public DeviceType {
 public:
  FileDeviceType(Device device, std::uint64_t hash)
      : device_(std::move(device)), description_{hash, device_.source} {}
  const DeviceDescription& description() const override { return description_; }
  std::unique_ptr<HapticDevice> make_finger(DevicePortHost& port, ClockMode clock,
                                            std::uint64_t haptic_session) const override {
    return std::make_unique<Driver>(device_.geometry, port, clock, haptic_session);
  }

 private:
  Device device_;
  DeviceDescription description_;
};

// The SPIDAR: four strings per finger from alternate corners of a cube (common/spidar/geometry.h); its argument is a
// device file, the built-in geometry without one.
std::unique_ptr<DeviceType> parse_spidar(const std::string& argument) {
  SpidarDevice spidar = parse_device_spec(argument.empty() ? "spidar" : "spidar:" + argument);
  const std::uint64_t hash = geometry_hash(spidar.geometry);
  return std::make_unique<FileDeviceType<SpidarDevice, SpidarDriver>>(std::move(spidar), hash);
}

// The grip SPIDAR: eight strings from the corners of a cube hold a grip, whose pose they read and on which they render
// force and torque (common/spidar/grip_geometry.h); one oriented finger, for a tool in the hand (docs/tool.md). Its
// argument is a grip device file, the built-in geometry without one.
std::unique_ptr<DeviceType> parse_grip(const std::string& argument) {
  GripDevice grip = parse_grip_spec(argument.empty() ? "grip" : "grip:" + argument);
  const std::uint64_t hash = grip_geometry_hash(grip.geometry);
  return std::make_unique<FileDeviceType<GripDevice, GripPortDriver>>(std::move(grip), hash);
}

// The web hand: a simulated hand steered from the viewer's page (web_hand.h); its argument is a hand file
// (web_hand_params.h), the built-in hand without one. Its touch port is "<shm>.touch", which `viewer --touch` opens.
class WebHandType final : public DeviceType {
 public:
  explicit WebHandType(WebHandParams params)
      : params_(std::move(params)), description_{0, "web hand (" + params_.source + ")"} {}
  const DeviceDescription& description() const override { return description_; }
  std::unique_ptr<HapticDevice> make_finger(DevicePortHost&, ClockMode, std::uint64_t) const override {
    throw std::logic_error("the web hand has no device port");
  }
  bool uses_device_ports() const override { return false; }
  std::unique_ptr<HapticDevice> make_local(const std::string& shm, ClockMode clock) const override {
    if (clock != ClockMode::realtime) {
      throw std::invalid_argument("--device web needs --clock realtime: a person's pointer does not wait for "
                                  "lockstep turns");
    }
    return std::make_unique<WebHand>(params_, std::make_unique<ShmTouchPortHost>(shm));
  }

 private:
  WebHandParams params_;
  DeviceDescription description_;
};

std::unique_ptr<DeviceType> parse_web(const std::string& argument) {
  return std::make_unique<WebHandType>(argument.empty() ? WebHandParams{} : load_web_hand(argument));
}

constexpr DeviceEntry kDevices[] = {
    {"spidar", "FILE.json", parse_spidar},
    {"grip", "FILE.json", parse_grip},
    {"web", "FILE.json", parse_web},
};

}  // namespace

std::unique_ptr<HapticDevice> DeviceType::make_local(const std::string&, ClockMode) const {
  throw std::logic_error("this device is reached through device ports");
}

std::string device_forms() {
  std::vector<std::string> forms;
  for (const DeviceEntry& entry : kDevices) {
    forms.emplace_back(entry.name);
    if (!entry.argument.empty()) forms.push_back(std::string(entry.name) + ":" + std::string(entry.argument));
  }
  return one_of(forms);
}

std::unique_ptr<DeviceType> parse_device(const std::string& spec) {
  const std::size_t colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  const std::string argument = colon == std::string::npos ? "" : spec.substr(colon + 1);
  for (const DeviceEntry& entry : kDevices) {
    if (entry.name != name) continue;
    if (colon != std::string::npos && (argument.empty() || entry.argument.empty())) break;  // "NAME:" or no argument
    return entry.parse(argument);
  }
  throw std::invalid_argument("--device must be " + device_forms() + ", not '" + spec + "'");
}

AssembledDevice::AssembledDevice(const DeviceType& type, std::span<DevicePortHost* const> ports, ClockMode clock,
                                 std::uint64_t haptic_session) {
  if (ports.empty()) throw std::invalid_argument("a device needs at least one port");
  std::vector<HapticDevice*> fingers;
  for (DevicePortHost* port : ports) {
    fingers_.push_back(type.make_finger(*port, clock, haptic_session));
    fingers.push_back(fingers_.back().get());
  }
  if (fingers_.size() > 1) set_.emplace(fingers);
}

AssembledDevice::AssembledDevice(const DeviceType& type, const std::string& shm, ClockMode clock) {
  fingers_.push_back(type.make_local(shm, clock));
}

}  // namespace impetus
