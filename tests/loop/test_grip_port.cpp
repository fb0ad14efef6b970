// SPDX-License-Identifier: Apache-2.0
// The 8-string grip SPIDAR behind a device port (haptic_controller/device/grip_port_driver.h at the host end,
// spidar_sim/grip_node.h at the device end, an in-process port between): the pose the driver reads is the pose the hand
// holds, the strings render the commanded wrench on the device's next tick, and a device's safety rules hold —
// minimum output without a valid pose or when told so, a wrench beyond the motors scaled down and counted.

#include <catch2/catch.hpp>

#include "common/contract/rotation.h"
#include "common/link/inproc/inproc_device_port.h"
#include "haptic_controller/device/grip_port_driver.h"
#include "spidar_sim/grip_node.h"
#include "spidar_sim/grip_sim.h"

#include <algorithm>
#include <cmath>

using namespace impetus;
using Eigen::Vector3d;

namespace {

constexpr double kTick_s = 1e-3;

// A device end that publishes the states it is given (a device whose counts went wrong).
class ScriptedGrip final : public DeviceStepper {
 public:
  explicit ScriptedGrip(InProcessDevicePort& port) : port_(port) {}
  bool step_device() override {
    port_.latest_command(command);
    port_.publish_state(state);
    return true;
  }
  DeviceState state{};
  DeviceCommand command{};

 private:
  InProcessDevicePort& port_;
};

}  // namespace

TEST_CASE("grip port: the driver reads the pose the hand holds, and the strings render the commanded wrench on the "
          "device's next tick", "[grip]") {
  const SpidarGripGeometry geometry;
  const GripPose start{Vector3d(0.02, -0.01, 0.07), turn_quaternion(Vector3d(0.1, -0.15, 0.2))};
  InProcessDevicePort port(kTick_s);
  GripSim sim(geometry, GripHandParams{}, start);
  GripNode node(sim, port, 7);
  port.connect(node);
  GripPortDriver driver(geometry, port, ClockMode::lockstep, 3);
  REQUIRE(driver.wait_attached());
  // A wrench the motors can render anywhere near the centre: 1 N along x and 0.02 N·m about z.
  const Vector3d force_N(1.0, 0.0, 0.0), torque_Nm(0.0, 0.0, 0.02);
  double worst_m = 0.0, worst_rad = 0.0, worst_N = 0.0, worst_Nm = 0.0;
  for (std::uint64_t tick = 0; tick < 500; ++tick) {
    const FingerSample* sample = driver.read(tick, static_cast<double>(tick) * kTick_s);
    REQUIRE(sample != nullptr);
    REQUIRE(sample->valid);
    worst_m = std::max(worst_m, (sample->position_m - sim.pose().position_m).norm());
    worst_rad = std::max(worst_rad, sample->orientation.angularDistance(sim.pose().orientation));
    if (tick > 0) {  // the strings' wrench over the tick just done is the last tick's command
      const GripWrench strings = sim.wrench();
      worst_N = std::max(worst_N, (strings.head<3>() - force_N).norm());
      worst_Nm = std::max(worst_Nm, (strings.tail<3>() - torque_Nm).norm());
    }
    FingerCommand command;
    command.force_N = force_N;
    command.torque_Nm = torque_Nm;
    command.render = true;
    REQUIRE(driver.command_fingers(tick, &command) == 0);
  }
  // The kinematics' accuracy from quantised counts (test_grip.cpp: 11 µm and 0.6 mrad at worst over the volume).
  CHECK(worst_m < 2e-5);
  CHECK(worst_rad < 1e-3);
  // The strings pull at the true pose with tensions solved at the measured one: a few newtons in each string turned by
  // the pose's error (~10⁻⁵ m over ~0.2 m strings, ~10⁻³ rad at the grip's 2 cm) leaves millinewtons.
  CHECK(worst_N < 5e-3);
  CHECK(worst_Nm < 2e-4);
  CHECK(driver.oriented());
  CHECK(driver.counters().saturations == 0);
  CHECK(driver.driver().counters().bad_readings == 0);
  CHECK(node.ticks() == 500);
}

TEST_CASE("grip port: without a valid pose, or told not to render, every string is at the motors' minimum, and a "
          "wrench beyond the motors is scaled down and counted", "[grip]") {
  const SpidarGripGeometry geometry;
  InProcessDevicePort port(kTick_s);
  ScriptedGrip device(port);
  port.connect(device);
  GripPortDriver driver(geometry, port, ClockMode::lockstep, 3);
  const GripStrings strings(geometry);
  const GripCounts at_centre = strings.encoder_counts(
      {Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]), Eigen::Quaterniond::Identity()});
  for (int k = 0; k < kGripStringCount; ++k) device.state.encoder_counts[k] = at_centre[static_cast<std::size_t>(k)];
  const auto sent_tensions = [&] {
    driver.read(0, 0.0);  // the device's turn: it takes the command sent last
    return device.command.tension_N;
  };

  REQUIRE(driver.read(0, 0.0)->valid);
  driver.command(0, Vector3d(1, 0, 0), false);
  for (int k = 0; k < kGripStringCount; ++k) CHECK(sent_tensions()[k] == geometry.tension_min_N);

  REQUIRE(driver.read(1, 0.0)->valid);
  CHECK_FALSE(driver.command(1, Vector3d(500, 0, 0), true));
  CHECK(driver.counters().saturations == 1);
  const auto scaled = sent_tensions();
  for (int k = 0; k < kGripStringCount; ++k) {
    CHECK(scaled[k] >= geometry.tension_min_N);
    CHECK(scaled[k] <= geometry.tension_max_N + 1e-9);
  }
  CHECK(*std::max_element(scaled.begin(), scaled.begin() + kGripStringCount) ==
        Approx(geometry.tension_max_N).epsilon(1e-9));  // a motor at its limit

  // One string 10 cm long: lengths no rigid pose has.
  device.state.encoder_counts[3] += static_cast<std::int64_t>(0.1 / geometry.metres_per_count);
  const FingerSample* bad = driver.read(2, 0.0);
  REQUIRE(bad != nullptr);
  CHECK_FALSE(bad->valid);
  CHECK(driver.driver().counters().bad_readings == 1);
  driver.command(2, Vector3d(1, 0, 0), true);
  for (int k = 0; k < kGripStringCount; ++k) CHECK(sent_tensions()[k] == geometry.tension_min_N);
}
