// SPDX-License-Identifier: Apache-2.0
// A rigid tool against the world in lockstep (haptic_controller/tool/tool_servo.h with world_manager's World): the
// world sends the planes of the objects near the tool, the tool's reaction, linear and angular, reaches the world
// through the same ledger as a finger's, and a struck cube turns as the 1 kHz world turns it.

#include <catch2/catch.hpp>

#include "tests/support/tool_strike.h"

#include <cmath>

using namespace impetus;
using Eigen::Vector3d;


using impetus::test::Strike;
using impetus::test::strike;

// The yaw against the 1 kHz world is measured, not asserted: 8 % off at 20 Hz under local coupling, where the goal is
// 5 % (docs/tool.md, "Against the world").
TEST_CASE("tool loop: a peg strikes a free cube off its centre: the world applies the linear and angular impulse "
          "the tool rendered, and the cube turns the way the 1 kHz world turns it") {
  const Strike reference = strike(1000.0, Coupling::impulse);
  CHECK(reference.yaw_rad < -0.05);  // pushed at +y of its centre along +x: it turns clockwise seen from above
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    CAPTURE(to_string(coupling));
    const Strike at_20 = strike(20.0, coupling);
    CHECK(at_20.rendered_Ns.x() > 0.05);
    CHECK(at_20.rendered_Nms.z() < 0.0);
    CHECK((at_20.applied_Ns - at_20.rendered_Ns).norm() <= 1e-12 * at_20.rendered_Ns.norm());
    CHECK((at_20.applied_Nms - at_20.rendered_Nms).norm() <= 1e-12 * at_20.rendered_Nms.norm());
    CHECK(at_20.yaw_rad < -0.05);
  }
}

using impetus::test::Lever;
using impetus::test::lever;

// The tipping angle against the 1 kHz world is measured in the benchmark and docs/tool.md, not asserted here: at 20 Hz
// local coupling overshoots it (its model does not know the box pivots on the ledge), and impulse coupling throws the
// box over.
TEST_CASE("tool loop: a hand levers a box up over a ledge's edge with a tool: the world applies what the tool "
          "rendered, and the box tips without going over") {
  const Lever reference = lever(1000.0, Coupling::impulse);
  CHECK(reference.peak_pitch_rad > 0.05);
  CHECK(reference.peak_pitch_rad < 0.2);
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    CAPTURE(to_string(coupling));
    const Lever at_20 = lever(20.0, coupling);
    CHECK(at_20.rendered_Ns.z() > 0.1);  // the tool pushes the box up
    CHECK((at_20.applied_Ns - at_20.rendered_Ns).norm() <= 1e-12 * at_20.rendered_Ns.norm());
    CHECK((at_20.applied_Nms - at_20.rendered_Nms).norm() <= 1e-12 * at_20.rendered_Nms.norm());
  }
  const Lever local = lever(20.0, Coupling::local);
  CHECK(local.peak_pitch_rad > 0.05);
  CHECK(local.peak_pitch_rad < 0.5);  // tipping over takes 0.59 rad (its centre of mass above the edge)
}
