// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/spidar_kinematics.h"

#include <catch2/catch.hpp>

#include <random>

using namespace impetus;
using Eigen::Vector3d;

TEST_CASE("SPIDAR: exact string lengths give the finger position back") {
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vector3d p = to_eigen(geometry.centre_m) + Vector3d(u(rng), u(rng), u(rng));
    Vector3d out;
    REQUIRE(kinematics.finger_position(kinematics.string_lengths_m(p), out));
    REQUIRE((out - p).norm() < 1e-12);
  }
}

TEST_CASE("SPIDAR round trip position -> counts -> position within one count's resolution") {
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  double worst_m = 0.0;
  for (int trial = 0; trial < 10000; ++trial) {
    const Vector3d p = to_eigen(geometry.centre_m) + Vector3d(u(rng), u(rng), u(rng));
    const EncoderCounts counts = kinematics.encoder_counts(p);
    Vector3d out;
    REQUIRE(kinematics.finger_position(counts, out));
    worst_m = std::max(worst_m, (out - p).norm());
  }
  INFO("worst error " << worst_m << " m, one count " << geometry.metres_per_count << " m");
  REQUIRE(worst_m <= geometry.metres_per_count);
}

TEST_CASE("SPIDAR: count 0 is length 0 (counts are absolute string lengths)") {
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  const StringLengths lengths = kinematics.string_lengths_m(EncoderCounts{0, 1, 1000, -3});
  REQUIRE(lengths[0] == 0.0);
  REQUIRE(lengths[1] == geometry.metres_per_count);
  REQUIRE(lengths[2] == Approx(1000 * geometry.metres_per_count));
  // The finger at a motor reports that string as zero counts.
  REQUIRE(kinematics.encoder_counts(kinematics.motor_m(2))[2] == 0);
}
