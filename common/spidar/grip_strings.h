// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the eight strings of the grip SPIDAR (grip_geometry.h) do at a pose of the grip: their lengths, the encoder
// counts they read, and the wrench matrix that maps their tensions to the force and torque on the grip. The grip's
// inverse kinematics, one description for the simulated hardware (spidar_sim) and the driver, whose forward
// kinematics solves these lengths for the pose (haptic_controller/device/grip_kinematics.h).
//
// Frames and units: world frame, z up, SI. A pose is the grip's centre and its orientation (grip → world). Encoder
// counts are absolute string lengths, length = count · metres_per_count, as for the 4-string device.

#include "common/spidar/grip_geometry.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>

namespace impetus {

struct GripPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();               // the grip's centre, world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();    // grip → world, unit
};

using GripLengths = std::array<double, kGripStringCount>;
using GripCounts = std::array<std::int64_t, kGripStringCount>;
using GripTensions = std::array<double, kGripStringCount>;
// Column k: [u_k; (R·a_k) × u_k], u_k the unit vector from string k's attachment toward its motor. W·t is the force
// (N) and the torque about the grip's centre (N·m) that tensions t (N) put on the grip, world frame.
using GripWrenchMatrix = Eigen::Matrix<double, 6, kGripStringCount>;
using GripWrench = Eigen::Matrix<double, 6, 1>;  // force (N), then torque about the grip's centre (N·m), world frame

class GripStrings {
 public:
  explicit GripStrings(const SpidarGripGeometry& geometry);

  const SpidarGripGeometry& geometry() const { return geometry_; }
  const Eigen::Vector3d& motor_m(int k) const { return motors_m_[k]; }
  const Eigen::Vector3d& attachment_m(int k) const { return attachments_m_[k]; }  // grip frame

  // The exact lengths at a pose, and the counts a device reports (nearest count).
  GripLengths lengths_m(const GripPose& pose) const;
  GripCounts encoder_counts(const GripPose& pose) const;
  GripLengths lengths_m(const GripCounts& counts) const;

  GripWrenchMatrix wrench_matrix(const GripPose& pose) const;

 private:
  SpidarGripGeometry geometry_;
  std::array<Eigen::Vector3d, kGripStringCount> motors_m_;
  std::array<Eigen::Vector3d, kGripStringCount> attachments_m_;  // grip frame
};

}  // namespace impetus
