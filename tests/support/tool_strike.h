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

// What the tool rendered on object `object` and what the world applied to it, linear and angular.
struct Ledger {
  Eigen::Vector3d rendered_Ns = Eigen::Vector3d::Zero(), applied_Ns = Eigen::Vector3d::Zero();
  Eigen::Vector3d rendered_Nms = Eigen::Vector3d::Zero(), applied_Nms = Eigen::Vector3d::Zero();
  double peak_force_N = 0.0;
};

// Plays `tool` against the world of `scene` at `world_rate_hz` under `coupling`, lockstep, for `ticks` ticks of 1 ms,
// calling after_step(world) after each world step; then two more steps apply the last reports. The grip is at
// grip_at(t), or with `hand` held by the hand (common/hand/grip_hand.h, defaults) whose target is grip_at(t) and which
// feels the rendered wrench, so the tool pushes as hard as a relaxed hand does.
template <typename GripAt, typename AfterStep>
Ledger play_tool(Scene scene, const ToolShape& tool, double world_rate_hz, Coupling coupling, int ticks,
                 std::size_t object, bool hand, GripAt&& grip_at, AfterStep&& after_step) {
  prepare_engines();
  scene.physics.world_rate_hz = world_rate_hz;
  WorldOptions options;
  options.coupling = coupling;
  World world(scene, options);
  ToolServo servo(tool, ToolCoupling{}, 1);
  const int ticks_per_step = static_cast<int>(std::lround(1000.0 / world_rate_hz));
  const BodyPose start = grip_at(0.0);
  GripHand holder(GripHandParams{}, GripPose{start.position_m, start.orientation});
  Ledger out;
  for (int tick = 0; tick < ticks + 2 * ticks_per_step; ++tick) {
    const double t_s = tick * kToolTick_s;
    if (tick % ticks_per_step == 0) {
      servo.on_plane_frame(world.step(&servo.report()), t_s);
      after_step(world);
    }
    if (tick >= ticks) continue;  // the world applies the last reports
    const BodyPose target = grip_at(t_s);
    const BodyPose grip = hand ? BodyPose{holder.pose().position_m, holder.pose().orientation} : target;
    const ToolTickResult& result = servo.tick(&grip, t_s, kToolTick_s);
    out.peak_force_N = std::max(out.peak_force_N, result.force_N.norm());
    if (!hand) continue;
    GripWrench wrench;
    wrench << result.force_N, result.torque_Nm;
    for (int k = 0; k < 10; ++k) {
      holder.step(GripPose{target.position_m, target.orientation}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                  wrench, kToolTick_s / 10);
    }
  }
  const HapticReport& report = servo.report();
  for (std::uint32_t e = 0; e < report.entry_count; ++e) {
    if (report.entries[e].object_id != static_cast<std::int32_t>(object)) continue;
    out.rendered_Ns += to_eigen(report.entries[e].impulse_Ns);
    out.rendered_Nms += to_eigen(report.entries[e].angular_impulse_Nms);
  }
  out.applied_Ns = world.total_impulse_Ns(object);
  out.applied_Nms = world.total_angular_impulse_Nms(object);
  return out;
}

struct Strike : Ledger {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // the cube's, at the end
  double yaw_rad = 0.0;
};

// The peg (10 mm square, its tip 5 mm above the floor) swung in +x at 0.3 m/s through the line y = 15 mm, off the
// cube's centre, for 0.25 s, then drawn back; the world runs 1.2 s in all. Another `tool` may swing instead.
inline Strike strike(double world_rate_hz, Coupling coupling, const ToolShape& tool = peg_tool()) {
  Strike out;
  const auto grip_at = [](double t_s) {
    const double x_m = t_s < 0.25 ? 0.3 * t_s : 0.075 - 0.3 * (t_s - 0.25);
    return BodyPose{Eigen::Vector3d(std::max(x_m, -0.05), 0.015, 0.055), Eigen::Quaterniond::Identity()};
  };
  static_cast<Ledger&>(out) =
      play_tool(strike_scene(world_rate_hz), tool, world_rate_hz, coupling, 1200, 0, false, grip_at,
                [&](const World& world) {
        const ObjectState& cube = world.states()[0];
        out.position_m = cube.pose.position_m;
        out.yaw_rad = turn_between(Eigen::Quaterniond::Identity(), cube.pose.orientation).z();
      });
  return out;
}

// A lever: a 6 × 4 × 3 cm box of 0.2 kg rests on a static ledge (its top at 4 cm, its edge at x = 5 cm) and overhangs
// it by 2 cm, its centre of mass 1 cm behind the edge. The hand brings the 2 cm cube tool (cube_tool) up under the
// overhang, centred at x = 6.5 cm, its target 8 mm past the box's bottom in 0.2 s, holds 0.3 s and lowers it: the box
// tips about the ledge's edge, as far as the hand's push holds it against its weight, and settles back.
inline Scene lever_scene() {
  Scene scene;
  scene.source_name = "tool lever";
  SceneObject box;
  box.name = "box";
  box.shape = box_shape(Eigen::Vector3d(0.03, 0.02, 0.015));
  box.dynamic = true;
  box.mass_kg = 0.2;
  box.position_m = {0.04, 0.0, 0.055};
  scene.objects.push_back(box);
  SceneObject ledge;
  ledge.name = "ledge";
  ledge.shape = box_shape(Eigen::Vector3d(0.05, 0.05, 0.02));
  ledge.position_m = {0.0, 0.0, 0.02};
  scene.objects.push_back(ledge);
  scene.haptic.reach_radius_m = 0.1;
  return scene;
}

struct Lever : Ledger {
  double peak_pitch_rad = 0.0;   // how far the box tipped up (about −y: its overhang rising)
  double end_pitch_rad = 0.0;    // at the end of the hold (0.5 s)
};

inline Lever lever(double world_rate_hz, Coupling coupling) {
  Lever out;
  // The cube's top (1 cm above the grip) from 7 mm below the box's bottom, its own bottom 1.3 cm above the floor.
  const auto grip_at = [](double t_s) {
    const double rise_m = 0.015 * std::clamp(t_s / 0.2, 0.0, 1.0) - 0.015 * std::clamp((t_s - 0.5) / 0.2, 0.0, 1.0);
    return BodyPose{Eigen::Vector3d(0.065, 0.0, 0.023 + rise_m), Eigen::Quaterniond::Identity()};
  };
  int steps = 0;
  const int end_step = static_cast<int>(std::lround(0.5 * world_rate_hz));
  static_cast<Ledger&>(out) = play_tool(lever_scene(), cube_tool(), world_rate_hz, coupling, 900, 0, true, grip_at,
                                        [&](const World& world) {
    const double pitch_rad = -turn_between(Eigen::Quaterniond::Identity(), world.states()[0].pose.orientation).y();
    out.peak_pitch_rad = std::max(out.peak_pitch_rad, pitch_rad);
    if (steps++ == end_step) out.end_pitch_rad = pitch_rad;
  });
  return out;
}

}  // namespace impetus::test
