// SPDX-License-Identifier: Apache-2.0
#pragma once
// The device port (docs/architecture.md §1, §2): a haptic node and its device, always on one machine. The host end
// belongs to the haptic side's device driver; the device end to the device (spidar_sim, or a real device's bridge).
// Transports (shared memory, in-process) encode, seal and validate, so both ends see only validated contract frames.
//
// Attach: one device at a time claims the port; a device that detaches or dies frees it and the next may attach.
// Lockstep: the host is the master; the device advances exactly once per turn. Real time: the device publishes
// states at its own rate and the host takes the newest.

#include "common/contract/frames.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"

#include <cstdint>
#include <string>

namespace impetus {

// Which device an end was configured for: a hash of its description (e.g. geometry_hash of a SPIDAR) and where the
// description came from, for messages. Both ends of a port must agree.
struct DeviceDescription {
  std::uint64_t hash = 0;
  std::string source;
};

// The haptic side's end. Used from the servo thread; no call allocates, and only lockstep_turn() and
// wait_for_device() block.
class DevicePortHost {
 public:
  virtual ~DevicePortHost() = default;

  // Lockstep: the attached device takes its turn for `tick` and its new state is returned; nullptr if no device is
  // attached, or it detached or died during the turn (its slot is then freed).
  virtual const DeviceState* lockstep_turn(std::uint64_t tick) = 0;
  // Real time: the newest state if the device published one within the device staleness limit (runtime/staleness.h)
  // of `now_s`, else nullptr (and a device that is gone loses its slot).
  virtual const DeviceState* latest_state(double now_s) = 0;
  virtual void send_command(const DeviceCommand& command) = 0;

  // Lockstep: blocks until a device is attached; false if a stop was requested first.
  virtual bool wait_for_device() = 0;
  // Lockstep: ends the session; a waiting device returns from its wait with `shutdown`.
  virtual void end_session() = 0;

  virtual std::uint64_t rejected_states() const = 0;
  // Devices that left mid-session without detaching (died, or stopped answering a lockstep turn).
  virtual std::uint64_t devices_lost() const = 0;
  // Writes that found their channel's sequence word odd at rest (scribbled, or a writer killed mid-write) and repaired
  // it (seqlock.h); 0 for transports without sequence words.
  virtual std::uint64_t channel_repairs() const { return 0; }
};

// The device's end.
class DevicePortClient {
 public:
  virtual ~DevicePortClient() = default;

  virtual ClockMode clock() const = 0;
  virtual double haptic_period_s() const = 0;  // the device's tick in lockstep

  // The newest valid command (whether or not it is new since the last call); false if none was ever sent. Invalid
  // commands are dropped and counted.
  virtual bool latest_command(DeviceCommand& out) = 0;
  virtual void publish_state(const DeviceState& state) = 0;
  virtual void publish_stats(const LoopStats& stats) = 0;

  // Lockstep: waits for the host's turn (ok), the end of the session (shutdown) or the host's death (peer_gone).
  virtual TurnResult wait_turn() = 0;
  virtual void finish_turn() = 0;
  // Leaves the port. In lockstep, call it inside a turn instead of publishing a state; the host then frees the slot.
  virtual void detach() = 0;
  // Real time: whether the host is still there (not real-time safe: may read /proc).
  virtual bool host_alive() const = 0;

  virtual std::uint64_t rejected_commands() const = 0;
  // Writes that found their channel's sequence word odd at rest (scribbled, or a writer killed mid-write) and repaired
  // it (seqlock.h); 0 for transports without sequence words.
  virtual std::uint64_t channel_repairs() const { return 0; }
};

}  // namespace impetus
