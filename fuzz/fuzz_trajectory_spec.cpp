// SPDX-License-Identifier: Apache-2.0
// Fuzz target: built-in trajectory specs (`NAME[:key=value,...]`) through make_builtin_trajectory. Expected outcomes:
// a Trajectory or a TrajectoryError; an accepted trajectory must evaluate to finite positions and velocities.

#include "spidar_sim/trajectory.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/trajectory_check.h"

#include <cstddef>
#include <cstring>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string spec(reinterpret_cast<const char*>(data), size);
  try {
    impetus::fuzz::check_trajectory(impetus::make_builtin_trajectory(spec));
  } catch (const impetus::TrajectoryError& error) {
    // A message quotes at most a short excerpt of the input, however large the input (fuzz/regressions/*.gen).
    FUZZ_CHECK(std::strlen(error.what()) < impetus::fuzz::kMaxMessageChars);
  }
  return 0;
}
