// SPDX-License-Identifier: Apache-2.0
#pragma once
// A 6-DoF haptic device as a tool servo sees it (docs/tool.md): the grip's pose in, a force and a torque out, within
// its limits. What it is made of — eight strings and their encoders (GripPortDriver), a linkage — stays behind this
// interface, as HapticDevice (haptic_device.h) hides a finger's device from the point servo.
//
// Called from the servo thread once per tick: read() first, then command(). Implementations do not allocate, lock or
// throw there; read() may block only in lockstep (the device's turn).

#include "common/shape/shape.h"
#include "haptic_controller/device/haptic_device.h"

#include <Eigen/Core>

#include <cstdint>

namespace impetus {

// The grip's reading: `valid` false when the device answered but its reading gives no pose (the strings do not fix
// it, a count jumped): the servo renders nothing and counts a fault.
struct GripSample {
  BodyPose pose;  // the grip's centre and orientation (grip → world), world frame
  bool valid = false;
};

struct ToolDeviceLimits {
  double max_force_N = 0.0;
  double max_torque_Nm = 0.0;  // about the grip's centre
};

class ToolDevice {
 public:
  virtual ~ToolDevice() = default;

  virtual const ToolDeviceLimits& limits() const = 0;
  // Lockstep: blocks until a device is attached; false if a stop was requested first (or it will never attach).
  virtual bool wait_attached() = 0;
  // The grip at haptic tick `tick` (time now_s); nullptr when no device is attached or its reading is stale.
  virtual const GripSample* read(std::uint64_t tick, double now_s) = 0;
  // Renders the wrench (force, torque about the grip's centre; world frame) on the grip read last; `render` false
  // commands the device's minimum output. Returns true if it was rendered exactly (false: scaled to the motors).
  virtual bool command(std::uint64_t tick, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm,
                       bool render) = 0;
  // Lockstep: ends the session (a waiting device is released).
  virtual void end_session() = 0;
  virtual DeviceCounters counters() const = 0;
};

}  // namespace impetus
