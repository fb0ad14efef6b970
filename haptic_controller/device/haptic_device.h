// SPDX-License-Identifier: Apache-2.0
#pragma once
// A haptic device as the servo sees it (docs/architecture.md §1.2): finger samples in, forces out, within its limits.
// What a device is made of — strings and encoders (SpidarDriver), linkages, a network bridge — stays behind this
// interface, so the servo is `tick(finger sample, dt) -> force` for any of them. An oriented device (oriented()) is a
// grip held in the hand: its sample has an orientation and its command a torque, for a tool's servo (docs/tool.md).
//
// Called from the servo thread once per tick: read() first, then command(). Implementations do not allocate, lock or
// throw there; read() may block only in lockstep (the device's turn).

#include "common/contract/frames.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cstdint>

namespace impetus {

// One finger's reading. `valid` is false when the device answered but its reading is unusable (non-finite, out of
// its workspace): the servo renders no force and counts a fault.
struct FingerSample {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // world frame
  // An oriented device's grip (HapticDevice::oriented): its turn, grip → world, unit; the identity for a finger.
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  bool valid = false;
  // False when this finger's part of a several-finger device is absent or stale while others answer: the servo then
  // gets no finger (minimum output, no fault), as when the whole device is absent.
  bool present = true;
};

// What the device can render; the servo clamps to it.
struct DeviceLimits {
  double max_force_N = 0.0;
  double max_torque_Nm = 0.0;  // an oriented device's, about the grip's centre; 0 for a finger
};

// What to render on one finger: `render` false commands the device's minimum output there.
struct FingerCommand {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_Nm = Eigen::Vector3d::Zero();  // an oriented device's, about the grip's centre
  bool render = false;
};

struct DeviceCounters {
  std::uint64_t saturations = 0;      // forces the device could render only approximately
  std::uint64_t rejected_frames = 0;  // readings its transport refused (checksum, range)
  std::uint64_t devices_lost = 0;     // devices that left mid-session without detaching
  std::uint64_t channel_repairs = 0;  // odd sequence words its transport found at rest and repaired
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  virtual const DeviceLimits& limits() const = 0;
  // The fingers it serves, 1 to kMaxFingers; constant for the device's lifetime.
  virtual std::uint32_t finger_count() const { return 1; }
  // Whether it is a 6-DoF device (a grip for a tool, docs/tool.md): its one finger is the grip, whose orientation
  // read() gives and whose torque command_fingers() renders. Constant for the device's lifetime.
  virtual bool oriented() const { return false; }

  // Lockstep: blocks until a device is attached; false if a stop was requested first (or it will never attach).
  virtual bool wait_attached() = 0;
  // The fingers at haptic tick `tick` (time now_s): finger_count() samples, finger k at index k; nullptr when no
  // device is attached or its reading is stale.
  virtual const FingerSample* read(std::uint64_t tick, double now_s) = 0;
  // Renders `force_N` on the (first) finger read last; `render` false commands the device's minimum output (no
  // finger, or a fault upstream). Returns true if the force was rendered exactly (false: saturated, the nearest
  // feasible force). A device of several fingers commands its others' minimum output.
  virtual bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) = 0;
  // Renders commands[k] on finger k, for all finger_count() fingers at once. Returns a bit per finger (bit k) that
  // was rendered only approximately (saturated); 0 if every force was exact. A one-finger device need not override.
  virtual std::uint32_t command_fingers(std::uint64_t tick, const FingerCommand* commands) {
    return command(tick, commands[0].force_N, commands[0].render) ? 0u : 1u;
  }
  // Whether the servos render a world (a world frame has reached them), told before each tick's command(): a device
  // may show it, and the simulated SPIDAR's scripted hand waits for it (kCommandWorldPresent). Default: ignored.
  virtual void note_world(bool present) { (void)present; }
  // Lockstep: ends the session (a waiting device is released).
  virtual void end_session() = 0;

  virtual DeviceCounters counters() const = 0;
  // What this kind of device counts beyond DeviceCounters, for summary.json's haptic.device (null: nothing).
  virtual nlohmann::json details() const { return nullptr; }
};

}  // namespace impetus
