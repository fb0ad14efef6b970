// SPDX-License-Identifier: Apache-2.0
// DeviceSim: the tick contract, tracking of the tap trajectory under the hand impedance, static deflection by the
// string force, and the log format.
#include "spidar_sim/device_sim.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <sstream>

using impetus::DeviceSim;
using impetus::FingerParams;
using impetus::HardwareParams;
using impetus::kStringCount;
using impetus::load_trajectory;
using impetus::SpidarGeometry;
using impetus::SpidarHardware;
using impetus::to_eigen;
using impetus::Trajectory;

namespace {

constexpr double kTick_s = 1e-3;
const std::array<double, kStringCount> kZeroTension{0.0, 0.0, 0.0, 0.0};

// Largest |target acceleration| (m/s²), by differencing the analytic velocity over the whole trajectory.
double max_target_acceleration(const Trajectory& trajectory) {
  constexpr double kDelta_s = 1e-5;
  double worst = 0.0;
  for (double t = 0.0; t <= trajectory.duration_s(); t += kDelta_s) {
    const Eigen::Vector3d dv = to_eigen(trajectory.velocity_at(t + kDelta_s)) - to_eigen(trajectory.velocity_at(t));
    worst = std::max(worst, dv.norm() / kDelta_s);
  }
  return worst;
}

// The tracking error e = target − x obeys m·ë + b·ė + k·e = m·ẍ_target − F_device (from m·ẍ = k·e + b·ė + F). For
// a forcing bounded by G_max, |e| ≤ ‖h‖₁·G_max, with h the impulse response of 1/(m s² + b s + k). For an
// underdamped h, ‖h‖₁ is the total variation of the step response: (1/k)·(1 + M)/(1 − M), M the overshoot.
double impulse_response_l1(const FingerParams& p) {
  const double zeta = p.hand_damping_Nspm / (2 * std::sqrt(p.hand_stiffness_Npm * p.mass_kg));
  const double overshoot = zeta < 1 ? std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta)) : 0.0;
  return (1 + overshoot) / (1 - overshoot) / p.hand_stiffness_Npm;
}

// Runs the trajectory to its end with constant commanded tensions; returns the largest |target − finger|.
double run_and_measure_tracking(DeviceSim& sim, const std::array<double, kStringCount>& tension_N) {
  double worst = 0.0;
  while (!sim.finished()) {
    sim.tick(tension_N, kTick_s);
    worst = std::max(worst, (to_eigen(sim.target_m()) - to_eigen(sim.finger_m())).norm());
  }
  return worst;
}

}  // namespace

TEST_CASE("with zero device force the finger tracks the tap within the hand-impedance bound") {
  SpidarGeometry slack;
  slack.tension_min_N = 0.0;  // a device that can let go completely: zero device force
  const FingerParams finger;
  const Trajectory tap = load_trajectory("tap");
  const double bound_m = impulse_response_l1(finger) * finger.mass_kg * max_target_acceleration(tap);
  DeviceSim sim(slack, HardwareParams{}, finger, tap);
  const double worst_m = run_and_measure_tracking(sim, kZeroTension);
  INFO("worst tracking error " << worst_m << " m, bound " << bound_m << " m");
  CHECK(worst_m <= bound_m);
  CHECK(worst_m > 0.1 * bound_m);  // the finger does lag: the bound is not met trivially
  // At the end the target has held still for 1.5 s (15 settling times): the finger is on it.
  CHECK((to_eigen(sim.target_m()) - to_eigen(sim.finger_m())).norm() < 1e-6);
  CHECK(sim.device_force_N() == impetus::Vec3{0.0, 0.0, 0.0});
}

TEST_CASE("with minimum tensions the finger tracks the tap within the bound including the idle string force") {
  const SpidarGeometry geometry;  // 0.5 N per string: they balance only at the frame centre
  const FingerParams finger;
  const Trajectory tap = load_trajectory("tap");
  const SpidarHardware idle(geometry, HardwareParams{});

  // Idle force along the target path, and how fast it can change as the finger strays from the path: ∂(t·u)/∂x has
  // norm t/L, so |F(x) − F(target)| ≤ Σ t_i/L_i · |e|, with L_i shortened by a 1 cm margin (checked below).
  constexpr double kMargin_m = 0.01;
  double idle_force_N = 0.0;
  double shortest_string_m = 1e9;
  for (double t = 0.0; t <= tap.duration_s(); t += 1e-4) {
    const Eigen::Vector3d p = to_eigen(tap.position_at(t));
    idle_force_N = std::max(idle_force_N, idle.force_on_finger(p).norm());
    for (const double length : idle.string_lengths_m(p)) shortest_string_m = std::min(shortest_string_m, length);
  }
  const double string_stiffness_Npm = kStringCount * geometry.tension_min_N / (shortest_string_m - kMargin_m);
  // |e| ≤ ‖h‖₁·(m·a_max + F_idle + K_s·|e|)  ⇒  |e| ≤ ‖h‖₁·(m·a_max + F_idle)/(1 − ‖h‖₁·K_s)
  const double l1 = impulse_response_l1(finger);
  const double bound_m =
      l1 * (finger.mass_kg * max_target_acceleration(tap) + idle_force_N) / (1 - l1 * string_stiffness_Npm);
  REQUIRE(bound_m < kMargin_m);

  DeviceSim sim(geometry, HardwareParams{}, finger, tap);
  const std::array<double, kStringCount> minimum{0.5, 0.5, 0.5, 0.5};
  const double worst_m = run_and_measure_tracking(sim, minimum);
  INFO("worst tracking error " << worst_m << " m, bound " << bound_m << " m, idle force " << idle_force_N << " N");
  CHECK(worst_m <= bound_m);
  // At rest at the end, the finger sits off the target by exactly the idle force over the hand stiffness.
  const Eigen::Vector3d offset = to_eigen(sim.finger_m()) - to_eigen(sim.target_m());
  CHECK((offset - to_eigen(sim.device_force_N()) / finger.hand_stiffness_Npm).norm() < 1e-6);
}

TEST_CASE("a constant string force deflects the finger by F/k_hand at rest") {
  const SpidarGeometry geometry;
  const FingerParams finger;
  const Trajectory hold = Trajectory::from_waypoints({{0.0, {0.02, -0.01, 0.06}}, {3.0, {0.02, -0.01, 0.06}}}, "hold");
  DeviceSim sim(geometry, HardwareParams{0.5e-3}, finger, hold);
  const std::array<double, kStringCount> pull_toward_motor_0{6.0, 0.5, 0.5, 0.5};
  while (!sim.finished()) sim.tick(pull_toward_motor_0, kTick_s);
  const Eigen::Vector3d force_N = to_eigen(sim.device_force_N());
  const Eigen::Vector3d deflection_m = to_eigen(sim.finger_m()) - to_eigen(sim.target_m());
  INFO("force " << force_N.transpose() << " N, deflection " << deflection_m.transpose() << " m");
  CHECK(force_N.norm() > 3.0);  // a centimetre-scale deflection, far above the encoder resolution
  CHECK((deflection_m - force_N / finger.hand_stiffness_Npm).norm() < 1e-9);
  CHECK(to_eigen(sim.finger_velocity_mps()).norm() < 1e-9);
}

TEST_CASE("tick contract: starts at rest on the trajectory start, counts the ticks, reports counts of the finger") {
  const SpidarGeometry geometry;
  const Trajectory tap = load_trajectory("tap:hold=0");
  DeviceSim sim(geometry, HardwareParams{}, FingerParams{}, tap);
  CHECK(sim.time_s() == 0.0);
  CHECK(sim.state().tick == 0);
  CHECK(sim.finger_m() == tap.position_at(0.0));
  CHECK(sim.finger_velocity_mps() == impetus::Vec3{0.0, 0.0, 0.0});
  CHECK(sim.tensions_N() == std::array<double, kStringCount>{0.5, 0.5, 0.5, 0.5});
  CHECK(sim.encoder_counts() == sim.hardware().encoder_counts(to_eigen(tap.position_at(0.0))));

  const auto& state = sim.tick({2.0, 1.0, 0.5, 3.0}, kTick_s);
  CHECK(state.tick == 1);
  CHECK(sim.time_s() == kTick_s);
  CHECK(sim.tensions_N() == std::array<double, kStringCount>{2.0, 1.0, 0.5, 3.0});
  CHECK(impetus::first_strings<kStringCount>(state.encoder_counts) ==
        sim.hardware().encoder_counts(to_eigen(sim.finger_m())));
  for (int k = kStringCount; k < impetus::kMaxDeviceStrings; ++k) {
    CHECK(state.encoder_counts[k] == 0);  // not this device's strings
  }
  CHECK(state.device_session == 0);  // the caller's to set

  int ticks = 1;
  while (!sim.finished()) {
    sim.tick(kZeroTension, kTick_s);
    ++ticks;
  }
  CHECK(sim.state().tick == static_cast<std::uint64_t>(ticks));
  CHECK(ticks == static_cast<int>(std::ceil(tap.duration_s() / kTick_s - 1e-9)));

  CHECK_THROWS_AS(sim.tick(kZeroTension, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(sim.tick(kZeroTension, std::nan("")), std::invalid_argument);
  CHECK_THROWS_AS(sim.tick(kZeroTension, 2.0), std::invalid_argument);
}

TEST_CASE("log rows have one value per header column, time first") {
  DeviceSim sim(SpidarGeometry{}, HardwareParams{}, FingerParams{}, load_trajectory("tap"));
  std::ostringstream log;
  DeviceSim::write_log_header(log);
  sim.tick(kZeroTension, kTick_s);
  sim.write_log_row(log);
  std::istringstream lines(log.str());
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  const auto columns = [](const std::string& line) { return std::count(line.begin(), line.end(), ',') + 1; };
  CHECK(columns(header) == 21);
  CHECK(columns(row) == columns(header));
  CHECK(header.rfind("time_s,", 0) == 0);
  CHECK(std::stod(row) == Approx(kTick_s));
}

TEST_CASE("a trajectory that leaves the device's frame is refused, naming the time and the point") {
  const SpidarGeometry geometry;  // a 0.4 m cube around (0, 0, 0.05)
  std::istringstream outside("t,x,y,z\n0,0,0,0.05\n1,5,0,0.05\n");
  const Trajectory far = impetus::parse_trajectory_csv(outside, "far.csv");
  CHECK_THAT(impetus::trajectory_problem(far, geometry),
             Catch::Contains("t = 1 s") && Catch::Contains("(5, 0, 0.05)") && Catch::Contains("0.4 m cube"));
  CHECK_THROWS_WITH(DeviceSim(geometry, HardwareParams{}, FingerParams{}, far), Catch::StartsWith("far.csv: "));
  // Every built-in the suite uses stays inside; an arc is looked at along its length, not only at its ends.
  for (const char* spec : {"tap", "press", "slide", "circle"}) {
    INFO(spec);
    CHECK(impetus::trajectory_problem(load_trajectory(spec), geometry).empty());
  }
  CHECK_FALSE(impetus::trajectory_problem(load_trajectory("circle:radius=0.3"), geometry).empty());
  // On the frame's face is inside.
  std::istringstream edge("t,x,y,z\n0,0,0,0.05\n1,0.2,0,0.05\n");
  CHECK(impetus::trajectory_problem(impetus::parse_trajectory_csv(edge, "edge.csv"), geometry).empty());
}

TEST_CASE("a held trajectory waits at its start, then plays as it would have from the start") {
  SpidarGeometry slack;
  slack.tension_min_N = 0.0;  // no device force: the finger at rest on a still target stays exactly there
  const Trajectory tap = load_trajectory("tap");
  DeviceSim held(slack, HardwareParams{}, FingerParams{}, tap);
  DeviceSim played(slack, HardwareParams{}, FingerParams{}, tap);
  const impetus::Vec3 start_m = held.finger_m();
  constexpr int kHeldTicks = 700;
  for (int k = 0; k < kHeldTicks; ++k) {
    held.hold_trajectory(kTick_s);
    held.tick(kZeroTension, kTick_s);
  }
  CHECK(held.finger_m() == start_m);
  CHECK(held.target_m() == start_m);
  CHECK(held.trajectory_time_s() == 0.0);
  CHECK(held.time_s() == Approx(kHeldTicks * kTick_s));
  // From the release on, the finger follows the same path, kHeldTicks later (the clocks differ by a rounding).
  double worst_m = 0.0;
  while (!played.finished()) {
    REQUIRE_FALSE(held.finished());
    played.tick(kZeroTension, kTick_s);
    held.tick(kZeroTension, kTick_s);
    worst_m = std::max(worst_m, (to_eigen(held.finger_m()) - to_eigen(played.finger_m())).norm());
  }
  CHECK(worst_m < 1e-9);
  CHECK(held.trajectory_time_s() == Approx(played.time_s()));
  held.tick(kZeroTension, kTick_s);  // the held one's clock lags by rounding only: at most one tick more
  CHECK(held.finished());
}
