// SPDX-License-Identifier: Apache-2.0
#pragma once
// A peg tool striking a free cube off its centre, in lockstep with the world (haptic_controller/tool/tool_servo.h,
// world_manager/world.h): shared by the loop's test and the tool's benchmark.

#include "common/contract/rotation.h"
#include "haptic_controller/tool/tool_servo.h"
#include "tests/support/tool_scenes.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace impetus::test {

// A 5 cm cube of 0.2 kg on the floor at x = 0.1 m; the world's reach covers the peg tool about its grip (5 cm).
inline Scene strike_scene(double world_rate_hz) {
  Scene scene;
  scene.source_name = "tool strike";
  SceneObject cube;
  cube.name = "cube";
  cube.shape = impetus::test::box_shape(Eigen::Vector3d(0.025, 0.025, 0.025));
  cube.dynamic = true;
  cube.mass_kg = 0.2;
  cube.position_m = {0.1, 0.0, 0.025};
  cube.material.static_friction = cube.material.dynamic_friction = 0.3;
  scene.objects.push_back(cube);
  scene.haptic.reach_radius_m = 0.1;
  scene.physics.world_rate_hz = world_rate_hz;
  return scene;
}

struct Strike {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // the cube's, at the end
  double yaw_rad = 0.0;
  Eigen::Vector3d rendered_Ns = Eigen::Vector3d::Zero(), applied_Ns = Eigen::Vector3d::Zero();
  Eigen::Vector3d rendered_Nms = Eigen::Vector3d::Zero(), applied_Nms = Eigen::Vector3d::Zero();
  double peak_force_N = 0.0;
};

// The peg (10 mm square, its tip 5 mm above the floor) swung in +x at 0.3 m/s through the line y = 15 mm, off the
// cube's centre, for 0.25 s, then drawn back; the world runs 1.2 s in all.
inline Strike strike(double world_rate_hz, Coupling coupling) {
  prepare_engines();
  const Scene scene = strike_scene(world_rate_hz);
  WorldOptions options;
  options.coupling = coupling;
  World world(scene, options);
  ToolCoupling tool_coupling;
  ToolServo servo(impetus::test::peg_tool(), tool_coupling, 1);
  const int ticks_per_step = static_cast<int>(std::lround(1000.0 / world_rate_hz));
  Strike out;
  for (int tick = 0; tick < 1200; ++tick) {
    const double t_s = tick * kToolTick_s;
    if (tick % ticks_per_step == 0) servo.on_plane_frame(world.step(&servo.report()), t_s);
    const double x_m = t_s < 0.25 ? 0.3 * t_s : 0.075 - 0.3 * (t_s - 0.25);
    const BodyPose grip{Eigen::Vector3d(std::max(x_m, -0.05), 0.015, 0.055), Eigen::Quaterniond::Identity()};
    const ToolTickResult& result = servo.tick(&grip, t_s, kToolTick_s);
    out.peak_force_N = std::max(out.peak_force_N, result.force_N.norm());
  }
  // The world applies the last reports.
  for (int k = 0; k < 2; ++k) servo.on_plane_frame(world.step(&servo.report()), 1.2);
  const ObjectState& cube = world.states()[0];
  out.position_m = cube.pose.position_m;
  out.yaw_rad = turn_between(Eigen::Quaterniond::Identity(), cube.pose.orientation).z();
  const HapticReport& report = servo.report();
  for (std::uint32_t e = 0; e < report.entry_count; ++e) {
    if (report.entries[e].object_id != 0) continue;
    out.rendered_Ns += to_eigen(report.entries[e].impulse_Ns);
    out.rendered_Nms += to_eigen(report.entries[e].angular_impulse_Nms);
  }
  out.applied_Ns = world.total_impulse_Ns(0);
  out.applied_Nms = world.total_angular_impulse_Nms(0);
  return out;
}

}  // namespace impetus::test
