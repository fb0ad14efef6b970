// SPDX-License-Identifier: Apache-2.0
#pragma once
// SPIDAR kinematics (docs/architecture.md §1.2 step 1): encoder counts ↔ string lengths ↔ finger position.
//
// Zero of the encoders: a count is an absolute string length, length_m = count · metres_per_count, so count 0 means
// the finger cap sits at the motor's string exit. The device (or spidar_sim) is calibrated that way at start-up; the
// driver never needs an offset. Geometry (motors at alternate corners of the frame cube) is SpidarGeometry's.

#include "common/spidar/geometry.h"
#include "common/contract/frames.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace impetus {

using EncoderCounts = std::array<std::int64_t, kStringCount>;
using StringLengths = std::array<double, kStringCount>;

class SpidarKinematics {
 public:
  explicit SpidarKinematics(const SpidarGeometry& geometry);

  StringLengths string_lengths_m(const EncoderCounts& counts) const;

  // Finger position (world frame) from the four string lengths: closed form from three squared-length differences,
  // refined by Gauss–Newton on all four lengths. Returns false (and leaves `finger_m` untouched) if the result is not
  // finite. Allocation-free.
  bool finger_position(const StringLengths& lengths_m, Eigen::Vector3d& finger_m) const;
  bool finger_position(const EncoderCounts& counts, Eigen::Vector3d& finger_m) const {
    return finger_position(string_lengths_m(counts), finger_m);
  }

  // Inverse kinematics: the exact string lengths for a finger position, and the encoder counts a device would report
  // (rounded to the nearest count). Used by tests and by spidar_sim.
  StringLengths string_lengths_m(const Eigen::Vector3d& finger_m) const;
  EncoderCounts encoder_counts(const Eigen::Vector3d& finger_m) const;

  const Eigen::Vector3d& motor_m(int string) const { return motors_m_[string]; }

 private:
  SpidarGeometry geometry_;
  std::array<Eigen::Vector3d, kStringCount> motors_m_;
  // Inverse of the 3×3 matrix of rows 2(m_i − m_0), i = 1..3, for the closed form.
  Eigen::Matrix3d difference_inverse_;
};

}  // namespace impetus
