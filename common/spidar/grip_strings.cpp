// SPDX-License-Identifier: Apache-2.0
#include "common/spidar/grip_strings.h"

#include <cmath>

namespace impetus {

GripStrings::GripStrings(const SpidarGripGeometry& geometry) : geometry_(geometry) {
  for (int k = 0; k < kGripStringCount; ++k) {
    motors_m_[k] = geometry.motor_m(k);
    attachments_m_[k] = geometry.attachment_m(k);
  }
}

GripLengths GripStrings::lengths_m(const GripPose& pose) const {
  const Eigen::Matrix3d rotation = pose.orientation.toRotationMatrix();
  GripLengths lengths{};
  for (int k = 0; k < kGripStringCount; ++k) {
    lengths[k] = (motors_m_[k] - pose.position_m - rotation * attachments_m_[k]).norm();
  }
  return lengths;
}

GripCounts GripStrings::encoder_counts(const GripPose& pose) const {
  const GripLengths lengths = lengths_m(pose);
  GripCounts counts{};
  for (int k = 0; k < kGripStringCount; ++k) {
    counts[k] = static_cast<std::int64_t>(std::llround(lengths[k] / geometry_.metres_per_count));
  }
  return counts;
}

GripLengths GripStrings::lengths_m(const GripCounts& counts) const {
  GripLengths lengths{};
  for (int k = 0; k < kGripStringCount; ++k) lengths[k] = static_cast<double>(counts[k]) * geometry_.metres_per_count;
  return lengths;
}

GripWrenchMatrix GripStrings::wrench_matrix(const GripPose& pose) const {
  const Eigen::Matrix3d rotation = pose.orientation.toRotationMatrix();
  GripWrenchMatrix w;
  for (int k = 0; k < kGripStringCount; ++k) {
    const Eigen::Vector3d arm = rotation * attachments_m_[k];
    const Eigen::Vector3d toward = motors_m_[k] - pose.position_m - arm;
    const double length = toward.norm();
    const Eigen::Vector3d u = length > 0.0 ? Eigen::Vector3d(toward / length) : Eigen::Vector3d::Zero();
    w.col(k).head<3>() = u;
    w.col(k).tail<3>() = arm.cross(u);
  }
  return w;
}

}  // namespace impetus
