// SPDX-License-Identifier: Apache-2.0
// SPIDAR hardware: string lengths and encoder counts follow the shared geometry, the applied tensions give the net
// force Σ t_i·u_i, commands are clamped to the motor limits, and the motor lag is first order.
#include "spidar_sim/spidar_hardware.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using impetus::HardwareParams;
using impetus::kStringCount;
using impetus::SpidarGeometry;
using impetus::SpidarHardware;

namespace {

// The motor corners as common/spidar/geometry.h describes them, written out independently of motor_positions_m().
std::array<Eigen::Vector3d, kStringCount> documented_motors(const SpidarGeometry& g) {
  const Eigen::Vector3d centre(g.centre_m[0], g.centre_m[1], g.centre_m[2]);
  const double h = g.frame_side_m / 2;
  return {centre + h * Eigen::Vector3d(+1, +1, +1), centre + h * Eigen::Vector3d(+1, -1, -1),
          centre + h * Eigen::Vector3d(-1, +1, -1), centre + h * Eigen::Vector3d(-1, -1, +1)};
}

Eigen::Vector3d random_point_in_frame(const SpidarGeometry& g, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.45 * g.frame_side_m, 0.45 * g.frame_side_m);
  return Eigen::Vector3d(g.centre_m[0] + u(rng), g.centre_m[1] + u(rng), g.centre_m[2] + u(rng));
}

SpidarHardware ideal_hardware(const SpidarGeometry& g) { return SpidarHardware(g, HardwareParams{}); }

}  // namespace

TEST_CASE("string lengths and encoder counts match the geometry") {
  const SpidarGeometry geometry;
  const SpidarHardware hardware = ideal_hardware(geometry);
  const auto motors = documented_motors(geometry);

  // At the centre every string is half the cube's space diagonal.
  const Eigen::Vector3d centre(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  for (const double length : hardware.string_lengths_m(centre)) {
    CHECK(length == Approx(geometry.frame_side_m * std::sqrt(3.0) / 2).epsilon(1e-14));
  }

  std::mt19937 rng(7);
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector3d finger = random_point_in_frame(geometry, rng);
    const auto lengths = hardware.string_lengths_m(finger);
    const auto counts = hardware.encoder_counts(finger);
    for (int i = 0; i < kStringCount; ++i) {
      const double expected_m = (motors[i] - finger).norm();
      CHECK(lengths[i] == Approx(expected_m).epsilon(1e-14));
      // Quantised to the nearest count: within half a count of the true length.
      CHECK(std::abs(counts[i] * geometry.metres_per_count - expected_m) <= 0.5 * geometry.metres_per_count);
    }
  }
}

TEST_CASE("moving the finger toward a motor by one count shortens that string by one count") {
  const SpidarGeometry geometry;
  const SpidarHardware hardware = ideal_hardware(geometry);
  const auto motors = documented_motors(geometry);
  // Start at a whole number of counts, the middle of its rounding interval, so rounding cannot blur the step.
  const Eigen::Vector3d centre(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  const Eigen::Vector3d u0 = (motors[0] - centre).normalized();
  const double length0 = (motors[0] - centre).norm();
  const double whole_counts = std::floor(length0 / geometry.metres_per_count);
  const Eigen::Vector3d start = motors[0] - u0 * whole_counts * geometry.metres_per_count;
  const auto before = hardware.encoder_counts(start);
  const auto after = hardware.encoder_counts(start + u0 * geometry.metres_per_count);
  CHECK(before[0] == static_cast<std::int64_t>(whole_counts));
  CHECK(after[0] == before[0] - 1);
}

TEST_CASE("commanded tensions produce the net force sum of t_i u_i") {
  const SpidarGeometry geometry;
  SpidarHardware hardware = ideal_hardware(geometry);
  const auto motors = documented_motors(geometry);
  const std::array<double, kStringCount> tensions{1.0, 2.5, 7.0, 13.0};
  hardware.apply(tensions, 1e-3);
  CHECK(hardware.tensions_N() == tensions);

  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d finger = random_point_in_frame(geometry, rng);
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int i = 0; i < kStringCount; ++i) expected += tensions[i] * (motors[i] - finger).normalized();
    CHECK((hardware.force_on_finger(finger) - expected).norm() < 1e-12);
  }
}

TEST_CASE("equal minimum tensions cancel at the centre only") {
  const SpidarGeometry geometry;
  const SpidarHardware hardware = ideal_hardware(geometry);  // idles at the minimum tension
  const Eigen::Vector3d centre(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  CHECK(hardware.force_on_finger(centre).norm() < 1e-15);
  // Off centre the four 0.5 N strings no longer balance (tap's strike point, 2.5 cm below and 3 cm beside the centre).
  CHECK(hardware.force_on_finger(centre + Eigen::Vector3d(-0.03, 0, -0.025)).norm() > 0.01);
}

TEST_CASE("commands are clamped to the motor limits") {
  const SpidarGeometry geometry;
  SpidarHardware hardware = ideal_hardware(geometry);
  hardware.apply({-5.0, 100.0, std::nan(""), 3.0}, 1e-3);
  const auto t = hardware.tensions_N();
  CHECK(t[0] == geometry.tension_min_N);
  CHECK(t[1] == geometry.tension_max_N);
  CHECK(t[2] == geometry.tension_min_N);  // a garbage setpoint leaves the string taut, not slack or runaway
  CHECK(t[3] == 3.0);
}

TEST_CASE("motor lag: first-order step response with the configured time constant") {
  const SpidarGeometry geometry;
  constexpr double tau_s = 2e-3;
  constexpr double step_N = 10.0;
  SpidarHardware hardware(geometry, HardwareParams{tau_s});
  const double t0 = geometry.tension_min_N;
  CHECK(hardware.tensions_N()[0] == t0);

  const std::array<double, kStringCount> command{step_N, step_N, step_N, step_N};
  const double dt = 1e-4;
  for (int k = 1; k <= 100; ++k) {
    hardware.apply(command, dt);
    const double expected = step_N + (t0 - step_N) * std::exp(-k * dt / tau_s);
    REQUIRE(hardware.tensions_N()[0] == Approx(expected).epsilon(1e-12));
  }
  // One time constant in: 63.2 % of the step.
  SpidarHardware fresh(geometry, HardwareParams{tau_s});
  fresh.apply(command, tau_s);
  CHECK((fresh.tensions_N()[0] - t0) / (step_N - t0) == Approx(1 - std::exp(-1.0)).epsilon(1e-12));
  // Zero time constant: the command is applied at once.
  SpidarHardware ideal = ideal_hardware(geometry);
  ideal.apply(command, 1e-6);
  CHECK(ideal.tensions_N()[0] == step_N);
}

TEST_CASE("unusable hardware parameters are rejected by name") {
  SpidarGeometry geometry;
  CHECK_THROWS_WITH(SpidarHardware(geometry, HardwareParams{-1.0}), Catch::Contains("motor_time_constant_s"));
  geometry.tension_max_N = 0.1;
  CHECK_THROWS_WITH(SpidarHardware(geometry, HardwareParams{}), Catch::Contains("tension_max_N"));
  geometry = SpidarGeometry{};
  geometry.metres_per_count = 0.0;
  CHECK_THROWS_WITH(SpidarHardware(geometry, HardwareParams{}), Catch::Contains("metres_per_count"));
}
