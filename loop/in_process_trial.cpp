// SPDX-License-Identifier: Apache-2.0
#include "loop/in_process_trial.h"

#include "loop/in_process_rig.h"

#include <mutex>
#include <stdexcept>

namespace impetus {

nlohmann::json run_in_process_trial(const InProcessTrialOptions& options) {
  if (!options.finger_paths.empty() && (!options.trajectory.empty() || !options.fingers.empty())) {
    throw std::invalid_argument("trajectory: give a trajectory, finger specs or finger paths, only one of them");
  }
  // Specs are checked as they are parsed (load_fingers); fingers made from arrays are checked here.
  if (!options.finger_paths.empty()) check_fingers(options.finger_paths, kMaxFingers);
  std::vector<NamedFinger> fingers =
      options.finger_paths.empty() ? load_fingers(options.trajectory, options.fingers) : options.finger_paths;
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  InProcessRig rig(options, std::move(fingers));
  rig.run();
  return rig.summary();
}

}  // namespace impetus
