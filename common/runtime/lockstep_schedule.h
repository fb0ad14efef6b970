// SPDX-License-Identifier: Apache-2.0
#pragma once
// The multi-rate schedule of `--clock lockstep` (docs/architecture.md §3): the haptic tick is the master clock and
// world step i happens at haptic tick i·n + phase, n = T_w / T the haptic ticks per world period.

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace impetus {

class LockstepSchedule {
 public:
  // n for a world period and haptic rate. Lockstep needs a whole number: throws std::invalid_argument naming both
  // otherwise (a period of 1/30 s is 33.3 ticks at 1 kHz).
  static std::uint64_t ticks_per_world_step(double world_period_s, double haptic_rate_hz) {
    const double ticks = world_period_s * haptic_rate_hz;
    // 1e-9: periods come from rates written in decimal (1/20 s × 1000 Hz = 50 up to rounding).
    if (!std::isfinite(ticks) || ticks < 1.0 || std::fabs(ticks - std::round(ticks)) > 1e-9) {
      throw std::invalid_argument("in lockstep the world period (" + std::to_string(world_period_s) +
                                  " s) must be a whole number of haptic ticks at " + std::to_string(haptic_rate_hz) +
                                  " Hz");
    }
    return static_cast<std::uint64_t>(std::llround(ticks));
  }

  LockstepSchedule(std::uint64_t ticks_per_step, std::uint64_t phase_ticks)
      : ticks_per_step_(ticks_per_step), phase_ticks_(phase_ticks) {}

  bool world_step_due(std::uint64_t tick) const {
    return tick >= phase_ticks_ && (tick - phase_ticks_) % ticks_per_step_ == 0;
  }
  std::uint64_t ticks_per_step() const { return ticks_per_step_; }

 private:
  std::uint64_t ticks_per_step_;
  std::uint64_t phase_ticks_;
};

}  // namespace impetus
