// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device port inside one process (docs/architecture.md §2 "In-process"): commands and states handed over as they
// are; the host's lockstep_turn() runs the device's tick on the caller's thread. Only lockstep: an in-process device
// has no clock of its own.

#include "common/link/device_port.h"

namespace impetus {

// What the in-process port calls for a device tick (the device node implements it). Returns false when the device
// has finished and detaches instead of ticking.
class DeviceStepper {
 public:
  virtual ~DeviceStepper() = default;
  virtual bool step_device() = 0;
};

class InProcessDevicePort final : public DevicePortHost, public DevicePortClient {
 public:
  explicit InProcessDevicePort(double haptic_period_s) : haptic_period_s_(haptic_period_s) {}

  // The device whose step_device() each lockstep turn runs.
  void connect(DeviceStepper& device) { device_ = &device; }

  // Host end.
  const DeviceState* lockstep_turn(std::uint64_t) override {
    if (device_ == nullptr || detached_) return nullptr;
    state_pending_ = false;
    if (!device_->step_device()) {
      detached_ = true;
      return nullptr;
    }
    return state_pending_ ? &state_ : nullptr;
  }
  const DeviceState* latest_state(double) override { return nullptr; }  // lockstep only
  void send_command(const DeviceCommand& command) override {
    command_ = command;
    have_command_ = true;
  }
  bool wait_for_device() override { return device_ != nullptr && !detached_; }
  void end_session() override {}
  std::uint64_t rejected_states() const override { return 0; }
  std::uint64_t devices_lost() const override { return 0; }  // the in-process device cannot die apart

  // Device end.
  ClockMode clock() const override { return ClockMode::lockstep; }
  double haptic_period_s() const override { return haptic_period_s_; }
  bool latest_command(DeviceCommand& out) override {
    if (have_command_) out = command_;
    return have_command_;
  }
  void publish_state(const DeviceState& state) override {
    state_ = state;
    state_pending_ = true;
  }
  void publish_stats(const LoopStats& stats) override { stats_ = stats; }
  TurnResult wait_turn() override { return TurnResult::shutdown; }  // never waited on: lockstep_turn() drives it
  void finish_turn() override {}
  void detach() override { detached_ = true; }
  bool host_alive() const override { return true; }
  std::uint64_t rejected_commands() const override { return 0; }

  const LoopStats& device_stats() const { return stats_; }

 private:
  double haptic_period_s_;
  DeviceStepper* device_ = nullptr;
  bool detached_ = false;
  DeviceCommand command_{};
  bool have_command_ = false;
  DeviceState state_{};
  bool state_pending_ = false;
  LoopStats stats_{};
};

}  // namespace impetus
