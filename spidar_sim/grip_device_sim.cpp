// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/grip_device_sim.h"

#include "common/runtime/csv_line.h"

#include <stdexcept>

namespace impetus {
namespace {

std::array<double, 4> wxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

}  // namespace

GripDeviceSim::GripDeviceSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, Trajectory trajectory)
    : trajectory_(trajectory.description()), sim_(geometry, hand, std::move(trajectory)) {
  for (int k = 0; k < kStrings; ++k) state_.encoder_counts[k] = sim_.encoder_counts()[static_cast<std::size_t>(k)];
}

const DeviceState& GripDeviceSim::tick(const std::array<double, kStrings>& commanded_N, double dt_s) {
  if (!(dt_s <= kMaxTick_s)) throw std::invalid_argument("GripDeviceSim::tick: dt_s beyond kMaxTick_s");
  const GripCounts& counts = sim_.tick(commanded_N, dt_s);
  for (int k = 0; k < kStrings; ++k) state_.encoder_counts[k] = counts[static_cast<std::size_t>(k)];
  ++state_.tick;
  return state_;
}

nlohmann::json GripDeviceSim::summary_fields() const {
  const GripHandParams& hand = sim_.hand().params();
  const SpidarGripGeometry& geometry = sim_.strings().geometry();
  return {{"kind", "grip"},
          {"trajectory", trajectory_},
          {"hand_mass_kg", hand.mass_kg},
          {"hand_stiffness_Npm", hand.stiffness_Npm},
          {"hand_damping_Nspm", hand.damping_Nspm},
          {"hand_rotational_stiffness_Nmprad", hand.rotational_stiffness_Nmprad},
          {"hand_rotational_damping_Nmsprad", hand.rotational_damping_Nmsprad},
          {"frame_side_m", geometry.frame_side_m},
          {"grip_radius_m", geometry.grip_radius_m},
          {"metres_per_count", geometry.metres_per_count},
          {"tension_min_N", geometry.tension_min_N},
          {"tension_max_N", geometry.tension_max_N}};
}

const char* GripDeviceSim::log_header() {
  return "time_s,target_x_m,target_y_m,target_z_m,target_qw,target_qx,target_qy,target_qz,grip_x_m,grip_y_m,"
         "grip_z_m,grip_qw,grip_qx,grip_qy,grip_qz,force_x_N,force_y_N,force_z_N,torque_x_Nm,torque_y_Nm,"
         "torque_z_Nm,tension_0_N,tension_1_N,tension_2_N,tension_3_N,tension_4_N,tension_5_N,tension_6_N,"
         "tension_7_N,count_0,count_1,count_2,count_3,count_4,count_5,count_6,count_7";
}

GripLogRow GripDeviceSim::log_row() const {
  GripLogRow row{};
  row.time_s = sim_.time_s();
  const GripPose target = sim_.trajectory_target();
  const GripPose grip = sim_.pose();
  const GripWrench wrench = sim_.wrench();
  row.target_m = to_vec3(target.position_m);
  row.target_wxyz = wxyz(target.orientation);
  row.grip_m = to_vec3(grip.position_m);
  row.grip_wxyz = wxyz(grip.orientation);
  row.force_N = to_vec3(Eigen::Vector3d(wrench.head<3>()));
  row.torque_Nm = to_vec3(Eigen::Vector3d(wrench.tail<3>()));
  row.tension_N = sim_.tensions_N();
  row.encoder_counts = sim_.encoder_counts();
  return row;
}

void GripDeviceSim::format_log_row(std::ostream& out, const GripLogRow& row) {
  CsvLine line(out);
  line.number(row.time_s).numbers(row.target_m).numbers(row.target_wxyz).numbers(row.grip_m).numbers(row.grip_wxyz);
  line.numbers(row.force_N).numbers(row.torque_Nm).numbers(row.tension_N);
  for (std::int64_t count : row.encoder_counts) line.integer(count);
}

}  // namespace impetus
