// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated 8-string grip SPIDAR and the hand holding its grip, playing a trajectory of poses, as a device node
// runs it (device_node.h; spidar_sim --device grip): the grip's counterpart of DeviceSim. Each tick holds the
// commanded tensions over the tick (grip_sim.h) and returns the eight counts as the state to publish. Its log has a
// row a tick: the hand's target, the grip's pose, the strings' wrench, the tensions and the counts. No allocation
// after construction.

#include "common/contract/frames.h"
#include "common/contract/vec3.h"
#include "spidar_sim/grip_sim.h"
#include "spidar_sim/trajectory.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <ostream>

namespace impetus {

struct GripLogRow {
  double time_s;
  Vec3 target_m;
  std::array<double, 4> target_wxyz;  // grip → world, unit
  Vec3 grip_m;
  std::array<double, 4> grip_wxyz;
  Vec3 force_N;    // the strings' wrench on the grip
  Vec3 torque_Nm;  // about its centre
  std::array<double, kGripStringCount> tension_N;  // as applied
  std::array<std::int64_t, kGripStringCount> encoder_counts;
};

class GripDeviceSim {
 public:
  static constexpr int kStrings = kGripStringCount;
  // A real-time hiccup longer than this is a bug upstream, not a tick (as DeviceSim's).
  static constexpr double kMaxTick_s = 1.0;
  using LogRow = GripLogRow;

  // Throws TrajectoryError if the trajectory takes the grip out of the frame, std::invalid_argument for unusable
  // parameters (grip_sim.h).
  GripDeviceSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, Trajectory trajectory);

  // One tick of dt_s (finite, in (0, kMaxTick_s]) under the commanded tensions; the counts at its end, `tick`
  // incremented (the caller stamps the session).
  const DeviceState& tick(const std::array<double, kStrings>& commanded_N, double dt_s);
  double tension_min_N() const { return sim_.strings().geometry().tension_min_N; }
  void hold_trajectory(double dt_s) { sim_.hold_trajectory(dt_s); }
  bool finished() const { return sim_.finished(); }
  double time_s() const { return sim_.time_s(); }
  // The hand's and the frame's parameters and the trajectory, for the device summary.
  nlohmann::json summary_fields() const;

  static const char* log_header();
  LogRow log_row() const;
  static void format_log_row(std::ostream& out, const LogRow& row);

  const GripSim& sim() const { return sim_; }

 private:
  std::string trajectory_;  // its description, for the summary
  GripSim sim_;
  DeviceState state_{};
};

}  // namespace impetus
