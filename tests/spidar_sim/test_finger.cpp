// SPDX-License-Identifier: Apache-2.0
// Finger model: static deflection under a constant force, the hand's step response, and sub-step selection.
#include "spidar_sim/finger.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using impetus::Finger;
using impetus::FingerParams;

TEST_CASE("a constant force F deflects the finger by F/k_hand at rest") {
  const FingerParams params;
  const Eigen::Vector3d target(0.01, -0.02, 0.03);
  const Eigen::Vector3d force_N(1.2, -0.6, 2.1);
  Finger finger(params, target);
  // 3 s is ~30 settling times (4/(ζω) ≈ 0.1 s).
  for (int k = 0; k < 30000; ++k) finger.step(target, Eigen::Vector3d::Zero(), force_N, 1e-4);
  const Eigen::Vector3d deflection = finger.position_m() - target;
  CHECK((deflection - force_N / params.hand_stiffness_Npm).norm() < 1e-12);
  CHECK(finger.velocity_mps().norm() < 1e-12);
}

TEST_CASE("the hand's step response overshoots as its damping ratio predicts") {
  const FingerParams params;
  const double zeta = params.hand_damping_Nspm / (2 * std::sqrt(params.hand_stiffness_Npm * params.mass_kg));
  CHECK(zeta == Approx(0.73).margin(0.005));
  const double predicted_overshoot = std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta));
  const double omega_d = std::sqrt(params.hand_stiffness_Npm / params.mass_kg) * std::sqrt(1 - zeta * zeta);
  const double predicted_peak_s = std::numbers::pi / omega_d;

  Finger finger(params, Eigen::Vector3d::Zero());
  const Eigen::Vector3d target(0.01, 0, 0);
  const double h = 1e-4;
  double peak = 0.0;
  double peak_s = 0.0;
  for (int k = 1; k <= 5000; ++k) {
    finger.step(target, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), h);
    if (finger.position_m().x() > peak) {
      peak = finger.position_m().x();
      peak_s = k * h;
    }
  }
  // The integrator's decay-rate error is ~(b/m)·h/2 = 0.4 % (finger.h): allow 5 % of the overshoot itself.
  CHECK((peak - 0.01) / 0.01 == Approx(predicted_overshoot).epsilon(0.05));
  CHECK(peak_s == Approx(predicted_peak_s).epsilon(0.01));
}

TEST_CASE("sub-steps: ten per millisecond by default, more for a stiff hand") {
  Finger finger(FingerParams{}, Eigen::Vector3d::Zero());
  CHECK(finger.substeps_for(1e-3) == 10);
  CHECK(finger.substeps_for(1e-4) == 1);
  FingerParams stiff;
  stiff.hand_stiffness_Npm = 1e6;  // ω = 3162 rad/s: ω·h ≤ 0.05 needs h ≤ 15.8 µs, 64 steps per ms
  CHECK(Finger(stiff, Eigen::Vector3d::Zero()).substeps_for(1e-3) == 64);
}

TEST_CASE("unusable finger parameters are rejected by name") {
  FingerParams params;
  params.mass_kg = 0.0;
  CHECK_THROWS_WITH(Finger(params, Eigen::Vector3d::Zero()), Catch::Contains("mass_kg"));
  params = FingerParams{};
  params.hand_stiffness_Npm = std::nan("");
  CHECK_THROWS_WITH(Finger(params, Eigen::Vector3d::Zero()), Catch::Contains("hand_stiffness_Npm"));
  params = FingerParams{};
  params.hand_damping_Nspm = -1.0;
  CHECK_THROWS_WITH(Finger(params, Eigen::Vector3d::Zero()), Catch::Contains("hand_damping_Nspm"));
}
