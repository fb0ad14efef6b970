// SPDX-License-Identifier: Apache-2.0
// Fuzz target: trajectory CSV files, through parse_trajectory_csv (the body of load_trajectory_csv without the file).
// Expected outcomes: a Trajectory or a TrajectoryError. An accepted trajectory must evaluate to finite positions and
// velocities everywhere, since spidar_sim feeds them straight into the hand model at 1 kHz.

#include "spidar_sim/trajectory.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/trajectory_check.h"

#include <cstddef>
#include <cstring>
#include <cstdint>
#include <sstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    impetus::fuzz::check_trajectory(impetus::parse_trajectory_csv(in, "fuzz.csv"));
  } catch (const impetus::TrajectoryError& error) {
    // A message quotes at most a short excerpt of the input, however large the input (fuzz/regressions/*.gen).
    FUZZ_CHECK(std::strlen(error.what()) < impetus::fuzz::kMaxMessageChars);
  }
  return 0;
}
