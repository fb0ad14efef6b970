// SPDX-License-Identifier: Apache-2.0
#pragma once
// What trajectory.h promises about a trajectory that loaded: finite position and velocity at any time, including
// before the start, at and around the segment joins we can reach cheaply, and after the end.

#include "spidar_sim/trajectory.h"
#include "fuzz/fuzz_check.h"

#include <array>
#include <cmath>

namespace impetus::fuzz {

inline void check_trajectory(const Trajectory& trajectory) {
  const double duration = trajectory.duration_s();
  FUZZ_CHECK(std::isfinite(duration) && duration >= 0.0);
  // Fractions of the duration rather than fixed times: durations range from microseconds to centuries.
  constexpr std::array<double, 9> kFractions = {-1.0, 0.0, 1e-9, 0.1, 0.25, 0.5, 0.75, 1.0, 2.0};
  for (double fraction : kFractions) {
    const double t = fraction < 0.0 ? -1.0 : fraction * duration;
    FUZZ_CHECK(all_finite(trajectory.position_at(t)));
    FUZZ_CHECK(all_finite(trajectory.velocity_at(t)));
  }
  // The device tick evaluates at 1 kHz; sample the first second at that rate as the device would.
  for (int tick = 0; tick <= 1000; tick += 37) {
    const double t = tick * 1e-3;
    FUZZ_CHECK(all_finite(trajectory.position_at(t)));
    FUZZ_CHECK(all_finite(trajectory.velocity_at(t)));
  }
}

}  // namespace impetus::fuzz
