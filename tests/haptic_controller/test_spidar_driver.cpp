// SPDX-License-Identifier: Apache-2.0
// The SPIDAR driver alone (device/spidar_driver.h): encoder counts from its port become a finger sample, a force
// becomes tensions on the port, and what it does without a device or with a broken reading.

#include "common/link/inproc/inproc_device_port.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/device/tension_distribution.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace impetus;
using Eigen::Vector3d;

namespace {

// A device that reports a fixed finger position through the port and remembers the last command it received.
class FixedDevice final : public DeviceStepper {
 public:
  FixedDevice(InProcessDevicePort& port, const EncoderCounts& counts) : port_(port) {
    impetus::set_first_strings(counts, state_.encoder_counts);
  }
  bool step_device() override {
    if (port_.latest_command(command)) ++commands;
    ++state_.tick;
    port_.publish_state(state_);
    return true;
  }
  DeviceCommand command{};
  int commands = 0;

 private:
  InProcessDevicePort& port_;
  DeviceState state_{};
};

}  // namespace

TEST_CASE("spidar driver: the encoders' finger, and tensions whose string forces add up to the commanded force") {
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  const Vector3d finger = Eigen::Map<const Vector3d>(geometry.centre_m.data()) + Vector3d(0.01, -0.02, 0.005);
  InProcessDevicePort port(1e-3);
  FixedDevice device(port, kinematics.encoder_counts(finger));
  port.connect(device);
  SpidarDriver driver(geometry, port, ClockMode::lockstep, 9);
  CHECK(driver.limits().max_force_N == geometry.max_force_N);

  const FingerSample* sample = driver.read(0, 0.0);
  REQUIRE(sample != nullptr);
  REQUIRE(sample->valid);
  CHECK((sample->position_m - finger).norm() < 2 * geometry.metres_per_count);  // one count of resolution

  const Vector3d force_N(1.0, -2.0, 3.0);
  CHECK(driver.command(0, force_N, true));  // within the limits: rendered exactly
  driver.read(1, 1e-3);                     // the device sees the command on its next tick
  REQUIRE(device.commands == 1);
  CHECK(device.command.haptic_session == 9);
  Vector3d rendered_N = Vector3d::Zero();
  for (int i = 0; i < kStringCount; ++i) {
    CHECK(device.command.tension_N[i] >= geometry.tension_min_N);
    CHECK(device.command.tension_N[i] <= geometry.tension_max_N);
    rendered_N += device.command.tension_N[i] * (kinematics.motor_m(i) - sample->position_m).normalized();
  }
  CHECK((rendered_N - force_N).norm() < kSaturationTolerance_N);
  CHECK(driver.counters().saturations == 0);
}

TEST_CASE("spidar driver: no device gives no sample, a broken reading an invalid one, both command minimum tension") {
  SpidarGeometry broken;
  broken.metres_per_count = std::nan("");  // every string length non-finite
  InProcessDevicePort port(1e-3);
  SpidarDriver driver(broken, port, ClockMode::lockstep, 9);
  CHECK(driver.read(0, 0.0) == nullptr);  // nothing attached to the port
  CHECK(driver.command(0, Vector3d(0, 0, 5.0), true));
  DeviceCommand command;
  REQUIRE(port.latest_command(command));
  for (double tension : impetus::first_strings<impetus::kStringCount>(command.tension_N)) {
    CHECK(tension == broken.tension_min_N);
  }

  FixedDevice device(port, {1, 2, 3, 4});
  port.connect(device);
  const FingerSample* sample = driver.read(1, 1e-3);
  REQUIRE(sample != nullptr);
  CHECK(!sample->valid);
  driver.command(1, Vector3d(0, 0, 5.0), true);
  REQUIRE(port.latest_command(command));
  for (double tension : impetus::first_strings<impetus::kStringCount>(command.tension_N)) {
    CHECK(tension == broken.tension_min_N);
  }
}

TEST_CASE("spidar driver: its commands say whether the servos render a world, from the tick it is told") {
  const SpidarGeometry geometry;
  InProcessDevicePort port(1e-3);
  SpidarDriver driver(geometry, port, ClockMode::lockstep, 9);
  DeviceCommand command;
  driver.command(0, Vector3d::Zero(), false);
  REQUIRE(port.latest_command(command));
  CHECK(command.flags == 0);  // no world yet
  driver.note_world(true);
  driver.command(1, Vector3d::Zero(), false);
  REQUIRE(port.latest_command(command));
  CHECK(command.flags == kCommandWorldPresent);
  driver.note_world(false);
  driver.command(2, Vector3d::Zero(), false);
  REQUIRE(port.latest_command(command));
  CHECK(command.flags == 0);
}
