// SPDX-License-Identifier: Apache-2.0
#pragma once
// A simulated device of one or more fingers (docs/architecture.md §1.3): per finger a SPIDAR string set and a hand
// (DeviceSim) and the node that runs it on its device port. The daemon (spidar_sim) and the in-process loop build it
// the same way. Every finger plays its trajectory held at its end until the longest ends, so all run equally long.

#include "common/link/device_port.h"
#include "common/spidar/geometry.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/device_sim.h"
#include "spidar_sim/trajectory.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace impetus {

// The fingers a command line or a Python call names: one "finger" on `trajectory`, or NAME=TRAJECTORY per entry of
// `finger_specs` (give one or the other). Throws TrajectoryError or std::invalid_argument naming the file and field.
std::vector<NamedFinger> load_fingers(const std::string& trajectory, const std::vector<std::string>& finger_specs);

class SimulatedFingers {
 public:
  SimulatedFingers(std::vector<NamedFinger> fingers, const SpidarGeometry& geometry, const HardwareParams& hardware,
                   const FingerParams& finger);

  std::size_t size() const { return fingers_.size(); }
  const NamedFinger& finger(std::size_t k) const { return fingers_[k]; }
  // Finger k's node on `port` (which must outlive this), logging to endpoint_log_path(log_path, k) ("" for none).
  DeviceNode& attach(std::size_t k, DevicePortClient& port, const std::string& log_path, std::uint64_t device_session);
  DeviceNode& node(std::size_t k) { return *nodes_[k]; }
  DeviceSim& sim(std::size_t k) { return *sims_[k]; }  // finger k's hand and strings (a closed loop steers them)
  // Runs every attached node until its trajectory ends: finger 0 on this thread, the others on threads of their own
  // (in lockstep each waits for its own turn, which the haptic controller gives in finger order). Returns the worst
  // exit status.
  int run();
  // The device half of summary.json (fingers_summary).
  nlohmann::json summary() const;

 private:
  std::vector<NamedFinger> fingers_;
  std::vector<std::unique_ptr<DeviceSim>> sims_;
  std::vector<std::unique_ptr<DeviceNode>> nodes_;
};

}  // namespace impetus
