// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/spidar_kinematics.h"
#include "haptic_controller/device/tension_distribution.h"

#include <catch2/catch.hpp>

#include <random>

using namespace impetus;
using Eigen::Vector3d;

namespace {

std::array<Vector3d, kStringCount> motors(const SpidarGeometry& geometry) {
  const SpidarKinematics kinematics(geometry);
  std::array<Vector3d, kStringCount> m;
  for (int i = 0; i < kStringCount; ++i) m[i] = kinematics.motor_m(i);
  return m;
}

Vector3d force_of(const std::array<double, kStringCount>& t, const Vector3d& finger,
                  const std::array<Vector3d, kStringCount>& m) {
  Vector3d f = Vector3d::Zero();
  for (int i = 0; i < kStringCount; ++i) f += t[i] * (m[i] - finger).normalized();
  return f;
}

}  // namespace

TEST_CASE("tension mapping reproduces feasible forces with the least tension, within limits") {
  const SpidarGeometry geometry;
  const auto m = motors(geometry);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    // Within 3 cm of the centre: farther out some 10 N directions exceed what 20 N motors can pull.
    const Vector3d finger = to_eigen(geometry.centre_m) + 0.03 * Vector3d(u(rng), u(rng), u(rng));
    const Vector3d force = geometry.max_force_N * std::abs(u(rng)) * Vector3d(u(rng), u(rng), u(rng)).normalized();
    const TensionSolution s =
        distribute_tension(force, finger, m, geometry.tension_min_N, geometry.tension_max_N);
    INFO("finger " << finger.transpose() << " force " << force.transpose() << " achieved "
                   << s.achieved_force_N.transpose());
    REQUIRE(!s.saturated);
    REQUIRE((force_of(s.tension_N, finger, m) - force).norm() < kSaturationTolerance_N);
    REQUIRE((s.achieved_force_N - force_of(s.tension_N, finger, m)).norm() < 1e-12);
    double lowest = geometry.tension_max_N;
    for (const double t : s.tension_N) {
      REQUIRE(t >= geometry.tension_min_N);
      REQUIRE(t <= geometry.tension_max_N);
      lowest = std::min(lowest, t);
    }
    REQUIRE(lowest == Approx(geometry.tension_min_N).margin(1e-4));  // least tension: one string at its minimum
  }
}

TEST_CASE("zero force commands the minimum tension balance, not zero") {
  const SpidarGeometry geometry;
  const auto m = motors(geometry);
  const TensionSolution s = distribute_tension(Vector3d::Zero(), to_eigen(geometry.centre_m), m,
                                               geometry.tension_min_N, geometry.tension_max_N);
  REQUIRE(!s.saturated);
  for (const double t : s.tension_N) REQUIRE(t == Approx(geometry.tension_min_N).margin(1e-6));
}

TEST_CASE("infeasible forces saturate to the nearest feasible force") {
  const SpidarGeometry geometry;
  const auto m = motors(geometry);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> tension(geometry.tension_min_N, geometry.tension_max_N);
  for (int trial = 0; trial < 50; ++trial) {
    const Vector3d finger = to_eigen(geometry.centre_m) + 0.08 * Vector3d(u(rng), u(rng), u(rng));
    const Vector3d force = 100.0 * Vector3d(u(rng), u(rng), u(rng)).normalized();
    const TensionSolution s = distribute_tension(force, finger, m, geometry.tension_min_N, geometry.tension_max_N);
    REQUIRE(s.saturated);
    for (const double t : s.tension_N) {
      REQUIRE(t >= geometry.tension_min_N);
      REQUIRE(t <= geometry.tension_max_N);
    }
    const double error = (s.achieved_force_N - force).norm();
    // No tension vector in the box (random samples and all 16 corners) renders a force closer to the request.
    for (int sample = 0; sample < 4000; ++sample) {
      std::array<double, kStringCount> t;
      for (int i = 0; i < kStringCount; ++i) {
        t[i] = sample < 16 ? ((sample >> i) & 1 ? geometry.tension_max_N : geometry.tension_min_N) : tension(rng);
      }
      REQUIRE((force_of(t, finger, m) - force).norm() >= error - 1e-6);
    }
  }
}

TEST_CASE("a non-finite force commands minimum tensions and reports saturation") {
  const SpidarGeometry geometry;
  const auto m = motors(geometry);
  const TensionSolution s = distribute_tension(Vector3d(std::nan(""), 0, 0), to_eigen(geometry.centre_m), m,
                                               geometry.tension_min_N, geometry.tension_max_N);
  REQUIRE(s.saturated);
  for (const double t : s.tension_N) REQUIRE(t == geometry.tension_min_N);
}

TEST_CASE("the closed form on the exact-force line never renders worse than the 81 faces, and agrees at the centre") {
  const SpidarGeometry geometry;
  const auto m = motors(geometry);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int line_cases = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Fingers out to the rim of the workspace and forces up to twice the device's: both methods get used.
    const double reach_m = trial % 2 ? 0.03 : 0.1;
    const Vector3d finger = to_eigen(geometry.centre_m) + reach_m * Vector3d(u(rng), u(rng), u(rng));
    const Vector3d force = 2.0 * geometry.max_force_N * std::abs(u(rng)) * Vector3d(u(rng), u(rng), u(rng)).normalized();
    const TensionSolution fast = distribute_tension(force, finger, m, geometry.tension_min_N, geometry.tension_max_N);
    const TensionSolution faces =
        distribute_tension_by_faces(force, finger, m, geometry.tension_min_N, geometry.tension_max_N);
    INFO("finger " << finger.transpose() << " force " << force.transpose());
    const double fast_error = (fast.achieved_force_N - force).norm();
    const double faces_error = (faces.achieved_force_N - force).norm();
    // The faces carry the ε bias (ε·t/σ²): ~1e-5 N at the centre, but near the rim, where σ is small, enough to call a
    // reachable force saturated. The line has no bias.
    REQUIRE(fast_error <= faces_error + 1e-9);
    double lowest = geometry.tension_max_N;
    for (const double t : fast.tension_N) {
      REQUIRE(t >= geometry.tension_min_N);
      REQUIRE(t <= geometry.tension_max_N);
      lowest = std::min(lowest, t);
    }
    if (fast_error < 1e-9) {
      ++line_cases;
      REQUIRE(lowest == geometry.tension_min_N);  // least tension: one string exactly at its minimum
    }
    if (reach_m < 0.05 && !faces.saturated) {
      for (int i = 0; i < kStringCount; ++i) REQUIRE(fast.tension_N[i] == Approx(faces.tension_N[i]).margin(1e-3));
    }
  }
  CHECK(line_cases > 10000);  // most of these requests are solved on the line
}
