// SPDX-License-Identifier: Apache-2.0
#pragma once
// The spidar_sim process, as main.cpp's flags ask for it: attaches to a running haptic controller's device ports and
// plays the fingers' trajectories (or the grip's, --device grip) until they end; writes its summary at exit.

#include "common/hand/finger.h"
#include "common/runtime/lockstep.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/spidar_hardware.h"

#include <string>
#include <vector>

namespace impetus {

struct SpidarSimFlags {
  std::string trajectory_spec;
  std::vector<std::string> finger_specs;  // NAME=TRAJECTORY, once per finger (instead of trajectory_spec)
  ClockMode clock = ClockMode::realtime;
  std::string log_path;
  std::string summary_path;
  std::string shm = "impetus";
  double attach_timeout_s = 10.0;
  double world_wait_s = DeviceNode::kWorldWait_s;
  std::string device_spec = "spidar";
  HardwareParams hardware;
  FingerParams finger;
  std::vector<std::string> finger_flags_given;  // the finger's own flags the command line gave (not for a grip)
};

// Runs the process until every trajectory has ended; returns the exit status. Throws on bad input found while setting
// up: run_node reports it.
int run_spidar_sim(const SpidarSimFlags& flags);

}  // namespace impetus
