// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which objects are too light for impulse coupling at a world rate (paper §2.2; hard case 10).
//
// With impulse coupling an object's plane cannot give way between world steps, so a finger pushing it keeps pushing a
// face that stands still for up to a whole period, and the world then applies that period's impulse at once. The
// largest such impulse is the device's force limit held for a period, F_max·T_w; on a body of mass m it is a speed of
// F_max·T_w/m. Where that exceeds what a hand gives an object (kHandSpeed_mps), a push can launch the body (3 g balls
// at 10 Hz: 345 m/s), and local coupling (§6.3) is the coupling to use. The world manager warns at start-up.

#include "world_manager/scene.h"

#include <cstddef>
#include <string>

namespace impetus {

// Faster than a hand moves things on a desk (the fastest trajectory in the hard cases strikes at 2 m/s).
inline constexpr double kHandSpeed_mps = 2.0;

struct LightObjects {
  std::size_t count = 0;          // dynamic objects whose F_max·T_w/m exceeds kHandSpeed_mps
  std::string lightest_name;      // the lightest of them
  double lightest_mass_kg = 0.0;
  double lightest_speed_mps = 0.0;  // F_max·T_w/m for it
};

LightObjects light_for_impulse_coupling(const Scene& scene, double world_period_s, double max_force_N);

}  // namespace impetus
