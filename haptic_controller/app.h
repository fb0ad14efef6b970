// SPDX-License-Identifier: Apache-2.0
#pragma once
// The haptic controller process (docs/architecture.md §1.2), as main.cpp's flags ask for it: hosts the device, opens
// the world link, runs a HapticNode on them and writes the haptic half of summary.json at exit. Built into the
// executable only (it links the DDS transport).

#include "common/link/link_options.h"
#include "haptic_controller/haptic_node.h"

#include <string>

namespace impetus {

struct HapticControllerFlags {
  HapticNodeOptions options;
  std::string summary_path;
  std::string shm = "impetus";
  double world_wait_s = 10.0;
  std::string device_spec = "spidar";
  std::string world_shm;  // "": the same as --shm
  unsigned fingers = 1;
  std::string mesh_scene;
  std::string tool_scene;
  LinkOptions link_options;
};

// Runs the process until its node stops; returns the exit status. Throws on bad input found while setting up (a file
// that cannot be used, flags that do not go together): run_node reports it.
int run_haptic_controller(HapticControllerFlags& flags);

}  // namespace impetus
