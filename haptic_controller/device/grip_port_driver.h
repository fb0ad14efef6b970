// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 8-string grip SPIDAR behind a device port (docs/devices.md §8): an oriented HapticDevice (haptic_device.h; its one
// finger is the grip) made of the grip driver (grip_driver.h: eight counts → the grip's pose, a wrench → eight tensions)
// and the port the counts arrive on and the tensions leave by (common/link/device_port.h; the port's string arrays
// carry all eight). The port decides lockstep or real time, as for the finger's SpidarDriver: in lockstep read() gives
// the device its turn; in real time it takes the newest reading, or none if it is stale.

#include "common/link/device_port.h"
#include "common/runtime/lockstep.h"
#include "common/spidar/grip_geometry.h"
#include "haptic_controller/device/grip_driver.h"
#include "haptic_controller/device/haptic_device.h"

#include <cstdint>

namespace impetus {

class GripPortDriver final : public HapticDevice {
 public:
  // `port` must outlive the driver; `haptic_session` stamps the commands. The first pose is solved from the frame's
  // centre (a cold start converges across the working volume, grip_kinematics.h).
  GripPortDriver(const SpidarGripGeometry& geometry, DevicePortHost& port, ClockMode clock,
                 std::uint64_t haptic_session);

  const DeviceLimits& limits() const override { return limits_; }
  bool oriented() const override { return true; }
  bool wait_attached() override { return port_.wait_for_device(); }
  // The grip's pose from the newest counts; `valid` false when they give none (grip_kinematics.h says why).
  const FingerSample* read(std::uint64_t tick, double now_s) override;
  // A force with no torque.
  bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) override;
  // The force and torque of commands[0] on the grip read last: bit 0 set if they were scaled to the motors.
  std::uint32_t command_fingers(std::uint64_t tick, const FingerCommand* commands) override;
  void end_session() override { port_.end_session(); }
  // Said to the device in the commands' flags (kCommandWorldPresent): a scripted hand waits for it (device_node.h).
  void note_world(bool present) override { command_.flags = present ? kCommandWorldPresent : 0; }
  DeviceCounters counters() const override;
  nlohmann::json details() const override;

  const GripDriver& driver() const { return driver_; }

 private:
  GripDriver driver_;
  DevicePortHost& port_;
  ClockMode clock_;
  DeviceLimits limits_;
  FingerSample sample_;
  DeviceCommand command_{};
};

}  // namespace impetus
