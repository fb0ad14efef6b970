// SPDX-License-Identifier: Apache-2.0
// A rigid tool against the world in lockstep (haptic_controller/tool/tool_servo.h with world_manager's World): the
// world sends the planes of the objects near the tool, the tool's reaction, linear and angular, reaches the world
// through the same ledger as a finger's, and a struck cube turns as the 1 kHz world turns it.

#include <catch2/catch.hpp>

#include "common/mesh/mesh_body.h"
#include "tests/support/mesh_shapes.h"
#include "tests/support/tool_strike.h"

#include <cmath>
#include <filesystem>

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

// A tool may be a user's mesh: a small convex one touches by its corners and sharp edges, as the primitive of its
// form does (common/mesh/mesh_body.h). The peg as a mesh file strikes the cube as the box peg does.
TEST_CASE("tool loop: a peg read from a mesh file strikes the cube as the box peg does, and the ledger is exact") {
  const std::string file = (std::filesystem::temp_directory_path() / "impetus-mesh-peg.obj").string();
  impetus::test::write_obj(impetus::test::box_mesh(Vector3d(0.01, 0.01, 0.04)), file);
  ToolShape mesh_peg = impetus::test::peg_tool();
  mesh_peg.shape = MeshBody::load(file, Vector3d::Ones(), true).shape();
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    CAPTURE(to_string(coupling));
    const Strike box = strike(20.0, coupling), mesh = strike(20.0, coupling, mesh_peg);
    CHECK((mesh.applied_Ns - mesh.rendered_Ns).norm() <= 1e-12 * mesh.rendered_Ns.norm());
    CHECK((mesh.applied_Nms - mesh.rendered_Nms).norm() <= 1e-12 * mesh.rendered_Nms.norm());
    // The file's corners are floats (Assimp's), 1e-9 m off the box's: the same strike to a micrometre and a
    // microradian (5 nm and 16 nrad here).
    CHECK((mesh.position_m - box.position_m).norm() < 1e-6);
    CHECK(mesh.yaw_rad == Approx(box.yaw_rad).margin(1e-6));
  }
}

using impetus::test::Lever;
using impetus::test::lever;

// The tipping angle against the 1 kHz world at 20–50 Hz is measured in the benchmark and docs/tool.md, not asserted
// here: local coupling's model does not know the box pivots on the ledge (it lets the box rise as a free body, so the
// hand meets a softer box and the world's box hardly tips at 20 Hz), and impulse coupling throws the box over.
TEST_CASE("tool loop: a hand levers a box up over a ledge's edge with a tool: the world applies what the tool "
          "rendered, the box tips as the 1 kHz world's at 100 Hz, and no frame kicks the hand") {
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
  // At 100 Hz the local model's box stays near the world's within a period: held where the 1 kHz world holds it.
  const Lever local_100 = lever(100.0, Coupling::local);
  CHECK(local_100.end_pitch_rad == Approx(reference.end_pitch_rad).epsilon(0.05));
  // At 20 Hz each frame corrects the model by millimetres; the correction reaches the hand as a ramp over the period
  // (tool_proxy.h), not as a kick: the push stays within what the hand's 300 N/m spring gives over its target's 8 mm
  // past the box's bottom (2.4 N) plus the spring's overshoot, where a frame's correction thrown at the hand at once
  // drove it to the device's 10 N limit.
  const Lever local_20 = lever(20.0, Coupling::local);
  CHECK(local_20.peak_force_N < 3.0);
  CHECK(local_20.peak_pitch_rad < 0.5);  // tipping over takes 0.59 rad (its centre of mass above the edge)
}
