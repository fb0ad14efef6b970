// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/grip_node.h"

#include "common/contract/rotation.h"

namespace impetus {

GripNode::GripNode(GripSim& sim, DevicePortClient& port, std::uint64_t device_session)
    : sim_(sim), port_(port), session_(device_session), target_(sim.pose()), target_from_(sim.pose()) {
  state_.device_session = session_;
}

bool GripNode::step_device() {
  // Minimum tensions until a command arrives: the strings stay taut and render nothing.
  GripTensions tensions{};
  tensions.fill(sim_.strings().geometry().tension_min_N);
  DeviceCommand command;
  if (port_.latest_command(command)) {
    for (int k = 0; k < kGripStringCount; ++k) tensions[static_cast<std::size_t>(k)] = command.tension_N[k];
  }
  const double dt_s = port_.haptic_period_s();
  const Eigen::Vector3d velocity_mps = (target_.position_m - target_from_.position_m) / dt_s;
  const Eigen::Vector3d angular_velocity_radps = turn_between(target_from_.orientation, target_.orientation) / dt_s;
  const GripCounts& counts = sim_.tick(tensions, target_, velocity_mps, angular_velocity_radps, dt_s);
  target_from_ = target_;
  for (int k = 0; k < kGripStringCount; ++k) state_.encoder_counts[k] = counts[static_cast<std::size_t>(k)];
  state_.tick = ++ticks_;
  port_.publish_state(state_);
  return true;
}

}  // namespace impetus
