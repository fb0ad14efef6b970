// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated 8-string grip SPIDAR on a device port: the grip's counterpart of DeviceNode (device_node.h). Each tick
// takes the newest commanded tensions (the motors' minimum before the first), advances the simulated motors, strings
// and hand (grip_sim.h) toward the target pose its owner steers, and publishes the eight encoder counts.
//
// Lockstep only, one tick per step_device() (the in-process port's turn): a closed loop steers it (loop/tool_loop.h).
// spidar_sim plays the grip along a trajectory with a device node instead (grip_device_sim.h). No allocation after
// construction.

#include "common/link/device_port.h"
#include "common/link/inproc/inproc_device_port.h"
#include "spidar_sim/grip_sim.h"

#include <cstdint>

namespace impetus {

class GripNode final : public DeviceStepper {
 public:
  // `sim` and `port` must outlive the node. The hand's target starts where the grip is.
  GripNode(GripSim& sim, DevicePortClient& port, std::uint64_t device_session);

  // Where the hand's target is at the end of the next tick: it moves there along a straight line and turn over the
  // tick, then holds. Finite (the caller checks).
  void steer(const GripPose& target) { target_ = target; }
  const GripPose& target() const { return target_; }

  // One tick of the port's haptic period; always true (the hand plays until its owner ends the session).
  bool step_device() override;

  std::uint64_t ticks() const { return ticks_; }
  const GripSim& sim() const { return sim_; }

 private:
  GripSim& sim_;
  DevicePortClient& port_;
  std::uint64_t session_;
  GripPose target_;       // at the end of the next tick
  GripPose target_from_;  // at the end of the last
  DeviceState state_{};
  std::uint64_t ticks_ = 0;
};

}  // namespace impetus
