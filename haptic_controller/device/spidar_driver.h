// SPDX-License-Identifier: Apache-2.0
#pragma once
// The SPIDAR driver: a HapticDevice made of three parts, each testable alone (docs/architecture.md §1.2) —
//   SpidarKinematics      encoder counts → finger position;
//   distribute_tension    force on the finger → four string tensions within [t_min, t_max];
//   DevicePortHost        the port the counts arrive on and the tensions leave by (shared memory or in-process).
// The port decides lockstep or real time: in lockstep read() gives the device its turn; in real time it takes the
// newest reading, or none if it is stale.

#include "common/link/device_port.h"
#include "common/runtime/lockstep.h"
#include "common/spidar/geometry.h"
#include "haptic_controller/device/haptic_device.h"
#include "haptic_controller/device/spidar_kinematics.h"

#include <array>
#include <cstdint>

namespace impetus {

class SpidarDriver final : public HapticDevice {
 public:
  // `port` must outlive the driver; `haptic_session` stamps the commands.
  SpidarDriver(const SpidarGeometry& geometry, DevicePortHost& port, ClockMode clock, std::uint64_t haptic_session);

  const DeviceLimits& limits() const override { return limits_; }
  bool wait_attached() override { return port_.wait_for_device(); }
  const FingerSample* read(std::uint64_t tick, double now_s) override;
  bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) override;
  void note_world(bool present) override { command_.flags = present ? kCommandWorldPresent : 0; }
  void end_session() override { port_.end_session(); }
  DeviceCounters counters() const override;

 private:
  std::array<double, kStringCount> minimum_tensions() const;  // every string at t_min

  SpidarGeometry geometry_;
  SpidarKinematics kinematics_;
  std::array<Eigen::Vector3d, kStringCount> motors_m_;
  DevicePortHost& port_;
  ClockMode clock_;
  DeviceLimits limits_;
  FingerSample sample_;
  bool have_sample_ = false;  // this tick's read() gave a sample
  DeviceCommand command_{};
  std::uint64_t saturations_ = 0;
};

}  // namespace impetus
