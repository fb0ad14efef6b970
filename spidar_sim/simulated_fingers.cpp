// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/simulated_fingers.h"

#include "common/contract/frames.h"
#include "common/runtime/log_paths.h"

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace impetus {

std::vector<NamedFinger> load_fingers(const std::string& trajectory, const std::vector<std::string>& finger_specs) {
  if (!trajectory.empty() && !finger_specs.empty()) throw std::invalid_argument("give trajectory or fingers, not both");
  if (finger_specs.empty()) {
    // Built step by step: a throwing call inside a braced list of elements is cleaned up wrongly by GCC 12
    // (AddressSanitizer: stack-use-after-scope when the trajectory is bad).
    std::vector<NamedFinger> fingers;
    Trajectory path = load_trajectory(trajectory);
    fingers.push_back({"finger", std::move(path)});
    return fingers;
  }
  return parse_fingers(finger_specs, kMaxFingers);
}

SimulatedFingers::SimulatedFingers(std::vector<NamedFinger> fingers, const SpidarGeometry& geometry,
                                   const HardwareParams& hardware, const FingerParams& finger)
    : fingers_(std::move(fingers)) {
  double longest_s = 0.0;
  for (const NamedFinger& named : fingers_) longest_s = std::max(longest_s, named.trajectory.duration_s());
  for (const NamedFinger& named : fingers_) {
    sims_.push_back(std::make_unique<DeviceSim>(geometry, hardware, finger, named.trajectory.held_until(longest_s)));
  }
  nodes_.resize(fingers_.size());
}

DeviceNode& SimulatedFingers::attach(std::size_t k, DevicePortClient& port, const std::string& log_path,
                                     std::uint64_t device_session) {
  nodes_.at(k) = std::make_unique<DeviceNode>(*sims_.at(k), port,
                                              endpoint_log_path(log_path, static_cast<std::uint32_t>(k)),
                                              device_session);
  return *nodes_[k];
}

int SimulatedFingers::run() {
  std::vector<int> statuses(nodes_.size(), 0);
  std::vector<std::thread> threads;
  for (std::size_t k = 1; k < nodes_.size(); ++k) threads.emplace_back([&, k] { statuses[k] = nodes_[k]->run(); });
  statuses[0] = nodes_[0]->run();
  for (std::thread& thread : threads) thread.join();
  return *std::max_element(statuses.begin(), statuses.end());
}

nlohmann::json SimulatedFingers::summary() const { return fingers_summary(nodes_, fingers_); }

}  // namespace impetus
