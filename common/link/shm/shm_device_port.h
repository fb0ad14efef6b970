// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device port over shared memory (docs/architecture.md §2): one segment "<shm>.device" (device_port_layout.h),
// created by the haptic node, opened by the device. A device claims the port by swapping device_pid from 0 to its pid;
// to leave it sets `detaching` (in lockstep, inside its last turn); a dead device is noticed by the host (pid gone),
// which resets the turn and frees the slot.

#include "common/link/device_port.h"
#include "common/link/shm/device_port_layout.h"
#include "common/link/shm/latest_valid.h"

#include <string>

namespace impetus {

class ShmDevicePortHost final : public DevicePortHost {
 public:
  // Creates the port of finger `finger` (names.h: "<shm>.device" for finger 0) for a host ticking every
  // `haptic_period_s` with `device` (throws SegmentError if a live process owns it).
  ShmDevicePortHost(const std::string& shm, ClockMode clock, double haptic_period_s, const DeviceDescription& device,
                    unsigned finger = 0);

  const DeviceState* lockstep_turn(std::uint64_t tick) override;
  const DeviceState* latest_state(double now_s) override;
  void send_command(const DeviceCommand& command) override;
  bool wait_for_device() override;
  void end_session() override;
  std::uint64_t rejected_states() const override { return rejected_; }
  std::uint64_t devices_lost() const override { return devices_lost_; }
  std::uint64_t channel_repairs() const override { return repairs_; }

  const std::string& name() const { return segment_.name(); }

 private:
  const DeviceState* read_state();
  void release_device();

  Segment<DevicePortLayout> segment_;
  std::int32_t attached_pid_ = 0;
  std::uint64_t last_sequence_ = 0;
  wire::DeviceState state_wire_{};
  wire::DeviceCommand command_wire_{};
  DeviceState state_{};
  bool have_state_ = false;
  std::uint64_t devices_lost_ = 0;
  std::uint64_t repairs_ = 0;
  double fresh_s_ = 0.0;
  std::uint64_t rejected_ = 0;
};

class ShmDevicePortClient final : public DevicePortClient {
 public:
  // Opens "<shm>.device" (waiting up to `timeout_s` for the haptic node to create it) and claims its slot (waiting
  // up to `timeout_s` for a dead device's slot to be freed). Throws if the host runs another clock than `clock`,
  // was configured for another device than `device` (naming both descriptions), or a live device holds the slot.
  // `finger`: which finger's port (names.h) of a several-finger host.
  ShmDevicePortClient(const std::string& shm, ClockMode clock, double timeout_s, const DeviceDescription& device,
                      unsigned finger = 0);
  ~ShmDevicePortClient() override;

  ClockMode clock() const override { return segment_->clock; }
  double haptic_period_s() const override { return segment_->haptic_period_s; }
  bool latest_command(DeviceCommand& out) override;
  void publish_state(const DeviceState& state) override;
  void publish_stats(const LoopStats& stats) override;
  TurnResult wait_turn() override;
  void finish_turn() override;
  void detach() override;
  bool host_alive() const override { return segment_.creator_alive(); }
  std::uint64_t rejected_commands() const override { return commands_.rejected(); }
  std::uint64_t channel_repairs() const override { return repairs_; }

  const std::string& name() const { return segment_.name(); }

 private:
  Segment<DevicePortLayout> segment_;
  LatestValid<wire::DeviceCommand, DeviceCommand> commands_;
  std::uint64_t repairs_ = 0;
  wire::DeviceState state_wire_{};
  bool detached_ = false;
};

}  // namespace impetus
