// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/servo.h"
#include "haptic_controller/device/spidar_kinematics.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace impetus;
using impetus::test::make_frame;
using impetus::test::wire_plane;
using Eigen::Vector3d;

namespace {


// The floor (static, id 0) at z = 0 and the top of a dynamic 5 cm cube (id 1) at z = 0.05.
PlaneFrame cube_on_floor(std::uint64_t index) {
  PlaneFrame frame = make_frame({wire_plane(0, {0, 0, 0}, {0, 0, 1}, false), wire_plane(1, {0, 0, 0.05}, {0, 0, 1})},
                                index);
  frame.stiffness_Npm = 2000.0;
  return frame;
}

}  // namespace

TEST_CASE("servo: a finger pressing on a cube on the floor is pushed up and the cube is pushed down") {
  ServoOptions options;
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const Vector3d above(0.0, 0.0, 0.055);   // the finger arrives from above the cube...
  const Vector3d finger(0.0, 0.0, 0.047);  // ...and presses 3 mm into it
  TickResult r{};
  for (int tick = 1; tick <= 100; ++tick) {
    const FingerSample state = test::finger_at(kinematics, tick == 1 ? above : finger);
    r = servo.tick(&state, tick * 1e-3, 1e-3);
  }
  REQUIRE(r.finger_valid);
  REQUIRE(r.active_planes == 1);
  REQUIRE(r.proxy_m[2] == Approx(0.05).margin(1e-12));
  REQUIRE(r.force_N[2] == Approx(2000.0 * 0.003).margin(2000.0 * 2e-5));  // k·depth, within a count's resolution
  REQUIRE(r.render);
  REQUIRE(!r.fault);
  const HapticReport& report = servo.report();
  REQUIRE(report.tick == 100);
  REQUIRE(report.haptic_session == 5);
  REQUIRE(report.finger_valid == 1);
  REQUIRE(report.entry_count == 1);
  REQUIRE(report.entries[0].object_id == 1);
  REQUIRE(report.entries[0].impulse_Ns[2] < 0.0);
  REQUIRE(report.entries[0].impulse_Ns[2] == Approx(-servo.accumulator().total_impulse_Ns().norm()));
  REQUIRE(report.static_impulse_Ns[2] == 0.0);
}

TEST_CASE("servo: no device means no finger, minimum output, zero force, nothing accumulated") {
  ServoOptions options;
  HapticServo servo(options, 5);
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const TickResult& r = servo.tick(nullptr, 1e-3, 1e-3);
  REQUIRE(!r.finger_valid);
  REQUIRE(r.active_planes == 0);
  REQUIRE(Eigen::Vector3d(to_eigen(r.force_N)) == Vector3d::Zero());
  REQUIRE(!r.render);
  REQUIRE(servo.report().finger_valid == 0);
  REQUIRE(servo.counters().no_device_ticks == 1);
  REQUIRE(servo.accumulator().total_impulse_Ns() == Vector3d::Zero());
}

TEST_CASE("servo: an invalid finger sample gives zero force, minimum output and a counted fault") {
  ServoOptions options;
  HapticServo servo(options, 5);
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  FingerSample sample;
  sample.position_m = Vector3d(0.0, 0.0, 0.047);
  sample.valid = false;
  const TickResult& r = servo.tick(&sample, 1e-3, 1e-3);
  REQUIRE(r.fault);
  REQUIRE(!r.render);
  REQUIRE(Eigen::Vector3d(to_eigen(r.force_N)) == Vector3d::Zero());
  REQUIRE(servo.counters().faults == 1);
}

TEST_CASE("servo: lockstep interpolation weight is ticks since arrival / n, and a stale world keeps its planes") {
  ServoOptions options;
  options.stiffness_Npm = 500.0;  // the flag overrides the scene
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  PlaneFrame first = make_frame({wire_plane(1, {0, 0, 0.0}, {0, 0, 1})}, 0, 0.05);
  PlaneFrame second = make_frame({wire_plane(1, {0, 0, 0.01}, {0, 0, 1})}, 1, 0.05);
  servo.on_plane_frame(first, 0.0);
  servo.on_plane_frame(second, 0.05);
  const Vector3d finger(0.0, 0.0, -0.002);
  const FingerSample state = test::finger_at(kinematics, finger);
  const FingerSample arriving = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.02));  // first seen outside the surface
  servo.tick(&arriving, 0.05, 1e-3);
  for (int j = 0; j <= 50; j += 10) {
    const TickResult& r = servo.tick(&state, 0.05 + j * 1e-3, 1e-3);
    REQUIRE(r.interpolation_weight == Approx(j / 50.0));
    REQUIRE(servo.planes().planes[0].point_m.z() == Approx(0.01 * j / 50.0));
    REQUIRE(!r.world_stale);
  }
  const TickResult& stale = servo.tick(&state, 0.05 + 0.2, 1e-3);
  REQUIRE(stale.world_stale);
  REQUIRE(stale.interpolation_weight == 1.0);
  REQUIRE(servo.planes().planes[0].point_m.z() == Approx(0.01));
  REQUIRE(stale.force_N[2] == Approx(500.0 * 0.012).margin(500.0 * 2e-5));
}

TEST_CASE("servo: a finger that appears inside an object is not kicked out until it has left the object") {
  ServoOptions options;
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const FingerSample inside = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.045));  // 5 mm into the cube
  const FingerSample outside = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.052));
  for (int tick = 1; tick <= 20; ++tick) {
    const TickResult& r = servo.tick(&inside, tick * 1e-3, 1e-3);
    REQUIRE(r.active_planes == 0);
    REQUIRE(Eigen::Vector3d(to_eigen(r.force_N)) == Vector3d::Zero());
  }
  servo.tick(&outside, 0.021, 1e-3);  // out of the cube: its plane is armed from now on
  const TickResult& back_in = servo.tick(&inside, 0.022, 1e-3);
  REQUIRE(back_in.active_planes == 1);
  REQUIRE(back_in.force_N[2] > 0.0);

  // A finger that starts outside and is inside when the first planes arrive was driven in: it is pushed out.
  {
    HapticServo late(options, 6);
    const FingerSample approaching = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.08));
    late.tick(&approaching, 0.001, 1e-3);  // no world frame yet
    late.on_plane_frame(cube_on_floor(0), 0.002);
    const TickResult& pushed = late.tick(&inside, 0.003, 1e-3);
    REQUIRE(pushed.active_planes == 1);
    REQUIRE(pushed.force_N[2] > 0.0);
  }

  // The device goes away while the finger presses 5 mm into the cube and comes back 10 mm in: the cube is set back
  // by the 5 mm it sank meanwhile, so the finger meets the force it was pressing against, not k·10 mm.
  const FingerSample deeper = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.040));
  servo.tick(nullptr, 0.023, 1e-3);
  const TickResult& reattached = servo.tick(&deeper, 0.024, 1e-3);
  REQUIRE(reattached.active_planes == 1);
  REQUIRE(reattached.force_N[2] == Approx(2000.0 * 0.005).margin(2000.0 * 2e-5));  // within a count's resolution
}

TEST_CASE("servo: a finger that vanishes while pressing and comes back no deeper resumes the contact") {
  // A web page silent for 40 ms, a device unplugged for a moment: the finger rests where it was, 3 mm into the cube.
  // Disarming the cube would let the finger sink through it; it meets the force it was pressing against again.
  ServoOptions options;
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const FingerSample above = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.055));
  const FingerSample pressing = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.047));
  const FingerSample shallower = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.049));
  const FingerSample deeper = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.046));
  servo.tick(&above, 0.001, 1e-3);
  double pressed_N = 0.0;
  for (int tick = 2; tick <= 10; ++tick) pressed_N = servo.tick(&pressing, tick * 1e-3, 1e-3).force_N[2];
  REQUIRE(pressed_N > 5.0);  // 2000 N/m × 3 mm

  for (int tick = 11; tick <= 60; ++tick) REQUIRE(servo.tick(nullptr, tick * 1e-3, 1e-3).force_N[2] == 0.0);
  const TickResult& same = servo.tick(&pressing, 0.061, 1e-3);
  CHECK(same.active_planes == 1);
  CHECK(same.force_N[2] == Approx(pressed_N).margin(1e-9));

  // Vanishing again and coming back shallower: resumed, less force than before.
  servo.tick(nullptr, 0.062, 1e-3);
  const TickResult less = servo.tick(&shallower, 0.063, 1e-3);
  CHECK(less.active_planes == 1);
  CHECK(less.force_N[2] > 0.0);
  CHECK(less.force_N[2] < pressed_N);

  // An invalid sample ends the session too. Back 3 mm deeper than it was pressing (1 mm): the cube is set back by the
  // 3 mm, the finger meets what it pressed against, and on the way out the set-back cube lets go 1 mm early.
  FingerSample invalid = shallower;
  invalid.valid = false;
  servo.tick(&invalid, 0.064, 1e-3);
  const TickResult& sank = servo.tick(&deeper, 0.065, 1e-3);
  CHECK(sank.active_planes == 1);
  CHECK(sank.force_N[2] == Approx(less.force_N[2]).margin(1e-9));
  const FingerSample out_by_less = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.0495));
  for (int tick = 66; tick <= 70; ++tick) servo.tick(&out_by_less, tick * 1e-3, 1e-3);
  CHECK(servo.tick(&out_by_less, 0.071, 1e-3).force_N[2] == 0.0);
  // Out of the cube, it is whole again: pressed 1 mm, the finger feels k·1 mm.
  servo.tick(&above, 0.072, 1e-3);
  for (int tick = 73; tick <= 80; ++tick) servo.tick(&shallower, tick * 1e-3, 1e-3);  // the damper settles
  CHECK(servo.tick(&shallower, 0.081, 1e-3).force_N[2] == Approx(less.force_N[2]).epsilon(1e-3));
}

TEST_CASE("servo: the setback of a finger that sank while it was away is carried through further absences") {
  // A page starved of CPU loses the hand several times in one press: each time the finger comes back where it was,
  // or a little deeper, and the cube's surface stays where the press left it.
  ServoOptions options;
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const auto at_depth = [&](double depth_m) { return test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.05 - depth_m)); };
  const auto press = [&](const FingerSample& finger, double& now_s) {
    double force_N = 0.0;
    for (int tick = 0; tick < 10; ++tick) force_N = servo.tick(&finger, now_s += 1e-3, 1e-3).force_N[2];
    return force_N;
  };
  const auto vanish = [&](double& now_s) {
    for (int tick = 0; tick < 50; ++tick) servo.tick(nullptr, now_s += 1e-3, 1e-3);
  };
  double now_s = 0.0;
  press(at_depth(-0.005), now_s);                        // above the cube
  const double one_mm_N = press(at_depth(0.001), now_s);  // 1 mm in: k·1 mm
  REQUIRE(one_mm_N == Approx(2.0).margin(0.05));
  vanish(now_s);
  CHECK(press(at_depth(0.003), now_s) == Approx(one_mm_N).margin(0.05));  // back 2 mm deeper: set back by 2 mm
  CHECK(press(at_depth(0.0015), now_s) == 0.0);                          // 0.5 mm before the set-back surface
  vanish(now_s);
  CHECK(press(at_depth(0.004), now_s) == 0.0);  // 2.5 mm deeper again: still 0.5 mm before the surface
  CHECK(press(at_depth(0.005), now_s) == Approx(0.5 * one_mm_N).margin(0.05));
  // Out of the cube and in again: the cube is whole.
  press(at_depth(-0.001), now_s);
  CHECK(press(at_depth(0.001), now_s) == Approx(one_mm_N).margin(0.05));
}

TEST_CASE("servo: after a stall longer than the device's watchdog, a finger that sank into an object is not kicked") {
  // The servo presses 2 mm into the cube, then does not run for 2 s (SIGSTOP): the device's watchdog has let go of
  // the hand (spidar_sim/command_watchdog.h), which sank 9 mm into the cube. The first tick after must not render
  // k·9 mm at once, and the impulse of that tick is held for the watchdog's time at most, not the 2 s.
  ServoOptions options;
  HapticServo servo(options, 5);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(cube_on_floor(0), 0.0);
  const FingerSample above = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.052));
  const FingerSample pressing = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.048));
  const FingerSample sunk = test::finger_at(kinematics, Vector3d(0.0, 0.0, 0.041));
  servo.tick(&above, 0.001, 1e-3);
  double pressed_N = 0.0;
  for (int tick = 2; tick <= 10; ++tick) pressed_N = servo.tick(&pressing, tick * 1e-3, 1e-3).force_N[2];
  REQUIRE(pressed_N > 3.0);  // 2000 N/m × 2 mm
  const TickResult& resumed = servo.tick(&sunk, 2.010, 2.0);
  CHECK(resumed.force_N[2] <= pressed_N * (1.0 + 1e-12));  // no kick: at most what was felt before the stall
  CHECK(servo.counters().servo_stalls == 1);
  // Coming out of the cube and pressing again renders normally.
  servo.tick(&above, 2.011, 1e-3);
  const TickResult& again = servo.tick(&pressing, 2.012, 1e-3);
  CHECK(again.force_N[2] > 3.0);
  // A late tick within the watchdog's time is not a stall.
  servo.tick(&pressing, 2.040, 0.028);
  CHECK(servo.counters().servo_stalls == 1);
}
