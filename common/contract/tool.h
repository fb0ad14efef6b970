// SPDX-License-Identifier: Apache-2.0
#pragma once
// A rigid tool held by a 6-DoF endpoint (docs/tool.md): its shape placed in the grip's frame, and the coupling that
// ties its proxy to the grip. Plain data: a scene's "tool" block (docs/scene-format.md) is parsed into it, and the
// haptic side's tool servo (haptic_controller/tool/) renders it. Frames: the grip's (its centre, its axes); SI.

#include "common/shape/shape.h"

namespace impetus {

// The tool's shape placed in the grip's frame (its centre of mass and axes there), rigidly held by the endpoint, and
// its weight.
struct ToolShape {
  Shape shape;
  BodyPose placement;  // shape frame → grip frame (default: the grip's own)
  double mass_kg = 0.0;  // 0: weightless (the hand and the objects carry nothing of it)
  // The tool's mass times the scene's gravity, world frame, acting at the shape's centre (placement.position_m).
  Eigen::Vector3d weight_N = Eigen::Vector3d::Zero();
};

// The 6-DoF spring–damper between the tool's proxy and the grip, and the device's limits on the wrench it renders.
struct ToolCoupling {
  double stiffness_Npm = 2000.0;               // k: the point finger's default (paper §4.2.1)
  double damping_Nspm = 2.0;                   // b: k·T at 1 kHz, as the point finger's default (force_renderer.h)
  double rotational_stiffness_Nmprad = 20.0;   // k_r: k at a 10 cm lever, a hand-held tool's length
  double rotational_damping_Nmsprad = 0.02;    // b_r: k_r·T at 1 kHz
  // The device's limits: a wrench beyond either is scaled down whole (its direction kept), and its reaction with it.
  double max_force_N = 10.0;
  double max_torque_Nm = 0.5;
};

}  // namespace impetus
