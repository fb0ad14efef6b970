// SPDX-License-Identifier: Apache-2.0
// Real-time discipline: the servo's tick() and on_plane_frame() and the SPIDAR driver's read() and command() never
// touch the heap (counted by tests/support/allocation_counter.h; not in sanitizer builds, which own operator new).

#include <catch2/catch.hpp>
#include <cstdlib>

#include "common/link/inproc/inproc_device_port.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/servo.h"
#include "test_support.h"

#include "tests/support/allocation_counter.h"

using namespace impetus;
using impetus::test::start_counting_allocations;
using impetus::test::stop_counting_allocations;
using Eigen::Vector3d;
using impetus::test::make_frame;
using impetus::test::wire_plane;

#if IMPETUS_COUNT_ALLOCATIONS
namespace {

// A device whose finger follows `finger_m`, reported through its encoders.
class WanderingDevice final : public DeviceStepper {
 public:
  WanderingDevice(InProcessDevicePort& port, const SpidarKinematics& kinematics) : port_(port), kinematics_(kinematics) {}
  bool step_device() override {
    impetus::set_first_strings(kinematics_.encoder_counts(finger_m), state_.encoder_counts);
    port_.publish_state(state_);
    return true;
  }
  Vector3d finger_m = Vector3d::Zero();

 private:
  InProcessDevicePort& port_;
  const SpidarKinematics& kinematics_;
  DeviceState state_{};
};

}  // namespace

TEST_CASE("the servo tick and the SPIDAR driver allocate nothing over 10^4 ticks") {
  ServoOptions options;
  HapticServo servo(options, 3);
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  InProcessDevicePort port(1e-3);
  WanderingDevice device(port, kinematics);
  port.connect(device);
  SpidarDriver driver(geometry, port, ClockMode::lockstep, 3);
  PlaneFrame frame = make_frame({wire_plane(0, {0, 0, 0}, {0, 0, 1}, false), wire_plane(1, {0, 0, 0.05}, {0, 0, 1}),
                                 wire_plane(2, {0.03, 0, 0}, {-1, 0, 0}), wire_plane(3, {0, 0.02, 0}, {0, -1, 1})});
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    frame.planes[k].static_friction = 0.6;
    frame.planes[k].dynamic_friction = 0.4;
    frame.planes[k].velocity_mps = {0.01, 0.0, 0.0};
  }

  start_counting_allocations();
  for (int tick = 1; tick <= 10000; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % 50 == 1) {
      frame.frame_index = tick / 50;
      frame.planes[1].point_m[2] = 0.05 + 0.002 * std::sin(tick * 1e-3);
      frame.report_tick_applied = static_cast<std::uint64_t>(tick - 1);
      frame.report_session_applied = 3;
      servo.on_plane_frame(frame, now_s);
    }
    // The finger wanders through free space, the cube, the edge and the corner.
    const Vector3d finger(0.02 * std::sin(tick * 0.003), 0.015 * std::cos(tick * 0.002),
                          0.04 + 0.03 * std::sin(tick * 0.001));
    device.finger_m = finger;
    const FingerSample* sample = driver.read(static_cast<std::uint64_t>(tick), now_s);
    const TickResult& result = servo.tick(tick % 997 == 0 ? nullptr : sample, now_s, 1e-3);
    driver.command(static_cast<std::uint64_t>(tick), to_eigen(result.force_N), result.render);
  }
  REQUIRE(stop_counting_allocations() == 0);
  REQUIRE(servo.counters().ticks == 10000);
}

TEST_CASE("the allocation counter does count (the test above can fail)") {
  start_counting_allocations();
  // A call of operator new, not a new-expression: the compiler may elide an unused new-expression.
  void* p = ::operator new(sizeof(int));
  const long allocations = stop_counting_allocations();
  ::operator delete(p);
  REQUIRE(allocations == 1);
}
#endif
