// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/grip_port_driver.h"

#include "common/contract/tool.h"

namespace impetus {
namespace {

// The device's rated limits, the tool coupling's defaults (common/contract/tool.h): what the servo clamps to first.
// Beyond what the strings can give at a pose the distribution scales the wrench down and counts it (grip_tension.h).
DeviceLimits grip_limits() {
  const ToolCoupling defaults;
  return {defaults.max_force_N, defaults.max_torque_Nm};
}

GripCounts counts_of(const DeviceState& state) {
  GripCounts counts{};
  for (int k = 0; k < kGripStringCount; ++k) counts[static_cast<std::size_t>(k)] = state.encoder_counts[k];
  return counts;
}

}  // namespace

GripPortDriver::GripPortDriver(const SpidarGripGeometry& geometry, DevicePortHost& port, ClockMode clock,
                               std::uint64_t haptic_session)
    : driver_(geometry, GripPose{Eigen::Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]),
                                 Eigen::Quaterniond::Identity()}),
      port_(port),
      clock_(clock),
      limits_(grip_limits()) {
  static_assert(kGripStringCount <= kMaxDeviceStrings);
  command_.haptic_session = haptic_session;
  set_first_strings(driver_.command(GripWrench::Zero(), false), command_.tension_N);
}

const FingerSample* GripPortDriver::read(std::uint64_t tick, double now_s) {
  const DeviceState* state = clock_ == ClockMode::lockstep ? port_.lockstep_turn(tick) : port_.latest_state(now_s);
  if (state == nullptr) return nullptr;
  const GripPose* pose = driver_.read(counts_of(*state));
  sample_.valid = pose != nullptr;
  if (pose != nullptr) {
    sample_.position_m = pose->position_m;
    sample_.orientation = pose->orientation;
  }
  return &sample_;
}

bool GripPortDriver::command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) {
  FingerCommand command;
  command.force_N = force_N;
  command.render = render;
  return command_fingers(tick, &command) == 0;
}

std::uint32_t GripPortDriver::command_fingers(std::uint64_t tick, const FingerCommand* commands) {
  GripWrench wrench;
  wrench << commands[0].force_N, commands[0].torque_Nm;
  const std::uint64_t saturations_before = driver_.counters().saturations;
  set_first_strings(driver_.command(wrench, commands[0].render && sample_.valid), command_.tension_N);
  command_.tick = tick;
  port_.send_command(command_);
  return driver_.counters().saturations == saturations_before ? 0u : 1u;
}

DeviceCounters GripPortDriver::counters() const {
  DeviceCounters counters;
  counters.saturations = driver_.counters().saturations;
  counters.rejected_frames = port_.rejected_states();
  counters.devices_lost = port_.devices_lost();
  counters.channel_repairs = port_.channel_repairs();
  return counters;
}

nlohmann::json GripPortDriver::details() const {
  const GripDriverCounters& c = driver_.counters();
  return {{"kind", "grip"},           {"readings", c.readings},     {"bad_readings", c.bad_readings},
          {"saturations", c.saturations}, {"no_closure", c.no_closure}, {"most_iterations", c.most_iterations}};
}

}  // namespace impetus
