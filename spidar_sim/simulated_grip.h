// SPDX-License-Identifier: Apache-2.0
#pragma once
// spidar_sim --device grip: the 8-string grip SPIDAR and the hand holding it (grip_device_sim.h), attached to a running
// haptic controller's device port and run by a device node until its trajectory ends (docs/tool.md "On the daemons").

#include "common/hand/finger.h"
#include "common/runtime/lockstep.h"

#include <string>

namespace impetus {

struct SimulatedGripOptions {
  std::string device_spec = "grip";  // "grip" or "grip:FILE.json" (common/spidar/grip_geometry.h)
  std::string trajectory;            // a trajectory spec (trajectory.h); a CSV may turn the grip
  std::string shm;
  ClockMode clock = ClockMode::realtime;
  double attach_timeout_s = 10.0;
  double world_wait_s = 10.0;
  std::string log_path;      // "": none
  std::string summary_path;  // "": none
  // The hand's linear impedance comes from the finger's flags (--hand-stiffness, --hand-damping); its turn's stays
  // the grip hand's (common/hand/grip_hand.h).
  FingerParams hand;
};

// Runs the grip until its trajectory ends; returns the exit status. Throws for a bad device file or trajectory, or a
// port that cannot be attached, naming them.
int run_simulated_grip(const SimulatedGripOptions& options);

// Whether `device_spec` names the grip device ("grip" or "grip:...").
inline bool names_grip(const std::string& device_spec) {
  return device_spec == "grip" || device_spec.rfind("grip:", 0) == 0;
}

}  // namespace impetus
