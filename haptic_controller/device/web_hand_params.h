// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the web hand device is (web_hand.h): the simulated hand a person steers from the viewer's page, its workspace
// and its limits. Built in, or read from a JSON file (`--device web:FILE.json`) whose keys are the fields below, each
// optional (a missing one keeps its default). World frame, SI units.

#include "common/contract/vec3.h"
#include "common/hand/finger.h"

#include <string>

namespace impetus {

struct WebHandParams {
  // The fingertip and the hand that holds it: spidar_sim's defaults (common/hand/finger.h), so a trial steered from
  // a page feels like one the simulated SPIDAR plays. File keys: "mass_kg", "hand_stiffness_Npm",
  // "hand_damping_Nspm".
  FingerParams hand;
  // Where targets may go: a cube of `workspace_side_m` about `workspace_centre_m`, a desktop SPIDAR's volume (its
  // built-in geometry, common/spidar/geometry.h), so scenes made for it fit.
  Vec3 workspace_centre_m{0.0, 0.0, 0.05};
  double workspace_side_m = 0.4;
  // Where the fingertip waits before anyone touches: the workspace centre unless given.
  Vec3 rest_m{0.0, 0.0, 0.05};
  // The largest force rendered on the fingertip, as the SPIDAR's (geometry.h).
  double max_force_N = 10.0;
  // How fast the hand's target may follow the pointer: 1 m/s, a brisk reach across a desk. A pointer jumps (a click
  // far away, a wheel turn, a touch lifted and put down elsewhere); the hand travels there instead of striking
  // whatever lies between at the speed of a jump.
  double max_target_speed_mps = 1.0;
  std::string source = "built-in";  // the file it came from, for messages
};

// Reads a web hand file. Unknown keys and unusable values are errors naming the file and the key (InputError).
WebHandParams load_web_hand(const std::string& path);

}  // namespace impetus
