// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/spidar_driver.h"

#include "haptic_controller/device/tension_distribution.h"

namespace impetus {

SpidarDriver::SpidarDriver(const SpidarGeometry& geometry, DevicePortHost& port, ClockMode clock,
                           std::uint64_t haptic_session)
    : geometry_(geometry), kinematics_(geometry), port_(port), clock_(clock) {
  for (int i = 0; i < kStringCount; ++i) motors_m_[i] = kinematics_.motor_m(i);
  limits_.max_force_N = geometry.max_force_N;
  command_.haptic_session = haptic_session;
  set_first_strings(minimum_tensions(), command_.tension_N);
}

std::array<double, kStringCount> SpidarDriver::minimum_tensions() const {
  std::array<double, kStringCount> out{};
  out.fill(geometry_.tension_min_N);
  return out;
}

const FingerSample* SpidarDriver::read(std::uint64_t tick, double now_s) {
  const DeviceState* state = clock_ == ClockMode::lockstep ? port_.lockstep_turn(tick) : port_.latest_state(now_s);
  have_sample_ = state != nullptr;
  if (!have_sample_) return nullptr;
  sample_.valid =
      kinematics_.finger_position(first_strings<kStringCount>(state->encoder_counts), sample_.position_m);
  return &sample_;
}

bool SpidarDriver::command(std::uint64_t tick, const Eigen::Vector3d& force_N, bool render) {
  bool exact = true;
  command_.tick = tick;
  if (render && have_sample_ && sample_.valid) {
    const TensionSolution tensions = distribute_tension(force_N, sample_.position_m, motors_m_,
                                                        geometry_.tension_min_N, geometry_.tension_max_N);
    set_first_strings(tensions.tension_N, command_.tension_N);
    exact = !tensions.saturated;
    if (tensions.saturated) ++saturations_;
  } else {
    set_first_strings(minimum_tensions(), command_.tension_N);  // strings taut, no force
  }
  port_.send_command(command_);
  return exact;
}

DeviceCounters SpidarDriver::counters() const {
  DeviceCounters counters;
  counters.saturations = saturations_;
  counters.rejected_frames = port_.rejected_states();
  counters.devices_lost = port_.devices_lost();
  counters.channel_repairs = port_.channel_repairs();
  return counters;
}

}  // namespace impetus
