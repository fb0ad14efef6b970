// SPDX-License-Identifier: Apache-2.0
#pragma once
// The SPIDAR hardware as the haptic controller sees it through the device port: four motors that pull strings with
// the commanded tensions, and four encoders that report the string lengths (docs/architecture.md §1.2, device tick).
//
// Conventions shared with the driver (common/spidar/geometry.h):
//   string i runs from motor i's exit point `motor_positions_m()[i]` straight to the finger cap;
//   its length is the distance |finger − motor_i|, reported as count_i = round(length / metres_per_count), i.e. the
//   encoders are calibrated so that count 0 means the finger sits on the motor (an absolute length, no offset);
//   a tension t_i ≥ 0 pulls the finger toward motor i: F = Σ t_i·u_i with u_i = (motor_i − finger)/|motor_i − finger|.
// Not thread-safe; owned by one DeviceSim.

#include "common/spidar/geometry.h"
#include "common/contract/frames.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace impetus {

struct HardwareParams {
  // First-order lag between the commanded and the applied tension (motor electrical + amplifier response):
  // dt/dτ = (commanded − t)/τ. Real DC motor current loops settle in ~0.1–1 ms. 0 = ideal (applied at once).
  double motor_time_constant_s = 0.0;
};

class SpidarHardware {
 public:
  using Tensions = std::array<double, kStringCount>;
  using Counts = std::array<std::int64_t, kStringCount>;

  // Throws std::invalid_argument naming the offending field if the geometry or parameters are unusable.
  SpidarHardware(const SpidarGeometry& geometry, const HardwareParams& params);

  // Holds `commanded_tension_N` for dt_s: each command is clamped to [tension_min_N, tension_max_N] (a non-finite
  // command is treated as the minimum: the amplifier keeps the string taut) and the applied tension follows it with
  // the motor lag, exactly integrated for a constant command. dt_s > 0 (checked by the caller).
  void apply(const Tensions& commanded_tension_N, double dt_s);

  // Net force (N) of the applied tensions on a finger at `finger_m`: Σ t_i·u_i. A string whose length is zero pulls
  // in no defined direction and contributes nothing.
  Eigen::Vector3d force_on_finger(const Eigen::Vector3d& finger_m) const;

  // Unit vectors from the finger toward each motor; zero for a string of zero length.
  std::array<Eigen::Vector3d, kStringCount> string_directions(const Eigen::Vector3d& finger_m) const;
  std::array<double, kStringCount> string_lengths_m(const Eigen::Vector3d& finger_m) const;
  Counts encoder_counts(const Eigen::Vector3d& finger_m) const;

  // Tensions the motors apply now (N); start at the minimum so the strings are taut from the first tick.
  const Tensions& tensions_N() const { return tension_N_; }
  const SpidarGeometry& geometry() const { return geometry_; }
  const HardwareParams& params() const { return params_; }

 private:
  SpidarGeometry geometry_;
  HardwareParams params_;
  std::array<Eigen::Vector3d, kStringCount> motor_m_;
  Tensions tension_N_{};
};

}  // namespace impetus
