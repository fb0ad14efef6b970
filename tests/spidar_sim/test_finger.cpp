// SPDX-License-Identifier: Apache-2.0
// Finger model: static deflection under a constant force, the hand's step response (exact at any step), a target
// moving at constant speed, and sub-step selection.
#include "common/hand/finger.h"

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
  for (int k = 0; k < 3000; ++k) finger.step(target, Eigen::Vector3d::Zero(), force_N, 1e-3);
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

  // The step is exact (finger.h): the closed-form response at every 1 ms step, and the peak of a fine sampling.
  const double omega_radps = std::sqrt(params.hand_stiffness_Npm / params.mass_kg);
  const auto exact_m = [&](double t_s) {
    return 0.01 * (1.0 - std::exp(-zeta * omega_radps * t_s) *
                             (std::cos(omega_d * t_s) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(omega_d * t_s)));
  };
  const Eigen::Vector3d target(0.01, 0, 0);
  Finger coarse(params, Eigen::Vector3d::Zero());
  for (int k = 1; k <= 200; ++k) {
    coarse.step(target, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1e-3);
    REQUIRE(coarse.position_m().x() == Approx(exact_m(k * 1e-3)).margin(1e-14));
  }
  Finger fine(params, Eigen::Vector3d::Zero());
  double peak = 0.0;
  double peak_s = 0.0;
  const double h = 1e-5;
  for (int k = 1; k <= 50000; ++k) {
    fine.step(target, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), h);
    if (fine.position_m().x() > peak) {
      peak = fine.position_m().x();
      peak_s = k * h;
    }
  }
  CHECK((peak - 0.01) / 0.01 == Approx(predicted_overshoot).epsilon(1e-6));
  CHECK(peak_s == Approx(predicted_peak_s).margin(h));
}

TEST_CASE("a finger whose hand tracks a target at constant speed catches it up, the same at any step") {
  // m·ẍ = k·(vt − x) + b·(v − ẋ): the steady state moves at v with no lag (the damper pulls toward the target's
  // velocity, the spring's offset is zero). Started on the target at rest, both step lengths land on the same state.
  const FingerParams params;
  const Eigen::Vector3d speed_mps(0.3, -0.1, 0.0);
  Finger coarse(params, Eigen::Vector3d::Zero()), fine(params, Eigen::Vector3d::Zero());
  for (int k = 0; k < 500; ++k) coarse.step(speed_mps * (k * 1e-3), speed_mps, Eigen::Vector3d::Zero(), 1e-3);
  for (int k = 0; k < 5000; ++k) fine.step(speed_mps * (k * 1e-4), speed_mps, Eigen::Vector3d::Zero(), 1e-4);
  CHECK((coarse.position_m() - fine.position_m()).norm() < 1e-12);
  CHECK((coarse.position_m() - speed_mps * 0.5).norm() < 1e-6);  // caught up with the target after 0.5 s
  CHECK((coarse.velocity_mps() - speed_mps).norm() < 1e-6);
}

TEST_CASE("sub-steps: one per millisecond by default, as many as max_substep_s asks for") {
  Finger finger(FingerParams{}, Eigen::Vector3d::Zero());
  CHECK(finger.substeps_for(1e-3) == 1);
  CHECK(finger.substeps_for(2.5e-3) == 3);
  FingerParams fine;
  fine.max_substep_s = 1e-4;
  CHECK(Finger(fine, Eigen::Vector3d::Zero()).substeps_for(1e-3) == 10);
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
