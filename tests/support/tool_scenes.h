// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scenes for a rigid tool (haptic_controller/tool/tool_proxy.h), shared by its tests and its benchmark: objects as the
// servo's planes carry them, tools, and the closed loop of the hand, the device's lagging motors and the proxy.

#include "common/contract/rotation.h"
#include "common/hand/grip_hand.h"
#include "haptic_controller/tool/tool_proxy.h"
#include "tests/haptic_controller/test_support.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <vector>

namespace impetus::test {

inline constexpr double kToolTick_s = 1e-3;

inline PlaneSet make_tool_set(std::initializer_list<ContactPlane> planes) {
  PlaneSet set;
  for (const ContactPlane& plane : planes) set.planes[set.count++] = plane;
  return set;
}

// A box object (static unless `dynamic`) as the servo's planes carry it: its shape, centre and axes.
inline ContactPlane box_object(int id, const Eigen::Vector3d& centre_m, const Eigen::Vector3d& half_m,
                               bool dynamic = false, const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity()) {
  ContactPlane plane;
  plane.object_id = id;
  plane.flags = dynamic ? kPlaneDynamic : 0u;
  plane.shape = box_shape(half_m);
  plane.com_m = centre_m;
  plane.axes = axes;
  plane.point_m = centre_m + half_m.z() * axes.col(2);
  plane.normal = axes.col(2);
  return plane;
}

inline ContactPlane floor_plane(int id = 0) {
  ContactPlane plane;
  plane.object_id = id;
  plane.point_m = Eigen::Vector3d::Zero();
  plane.normal = Eigen::Vector3d::UnitZ();
  return plane;
}

inline PlaneSet set_of(std::initializer_list<ContactPlane> planes) { return make_tool_set(planes); }

inline BodyPose pose_at(const Eigen::Vector3d& position_m,
                        const Eigen::Vector3d& turn_rad = Eigen::Vector3d::Zero()) {
  return {position_m, turn_quaternion(turn_rad)};
}

// A 2 cm cube held at the grip's centre.
inline ToolShape cube_tool() { return {box_shape(Eigen::Vector3d(0.01, 0.01, 0.01)), BodyPose{}}; }

// A square hole of side 11 mm, 30 mm deep, cut out of four static boxes on a floor box: a 10 mm peg fits with
// 0.5 mm of clearance on each side. Its rim is at z = 0, its bottom at z = −30 mm.
inline PlaneSet hole_scene() {
  const double inner_m = 0.0055, wall_m = 0.02, depth_m = 0.03;
  return set_of({box_object(1, Eigen::Vector3d(inner_m + 0.5 * wall_m, 0, -0.5 * depth_m),
                            Eigen::Vector3d(0.5 * wall_m, inner_m + wall_m, 0.5 * depth_m)),
                 box_object(2, Eigen::Vector3d(-inner_m - 0.5 * wall_m, 0, -0.5 * depth_m),
                            Eigen::Vector3d(0.5 * wall_m, inner_m + wall_m, 0.5 * depth_m)),
                 box_object(3, Eigen::Vector3d(0, inner_m + 0.5 * wall_m, -0.5 * depth_m),
                            Eigen::Vector3d(inner_m, 0.5 * wall_m, 0.5 * depth_m)),
                 box_object(4, Eigen::Vector3d(0, -inner_m - 0.5 * wall_m, -0.5 * depth_m),
                            Eigen::Vector3d(inner_m, 0.5 * wall_m, 0.5 * depth_m)),
                 box_object(5, Eigen::Vector3d(0, 0, -depth_m - 0.01), Eigen::Vector3d(0.05, 0.05, 0.01))});
}

// A 10 × 10 × 40 mm peg whose centre is 30 mm below the grip's: its tip 50 mm below the grip.
inline ToolShape peg_tool() {
  return {box_shape(Eigen::Vector3d(0.005, 0.005, 0.02)),
          BodyPose{Eigen::Vector3d(0, 0, -0.03), Eigen::Quaterniond::Identity()}};
}

// The hand holding the grip (common/hand/grip_hand.h) pressing the cube tool into a corner of the floor and a wall,
// turned, through a device whose motors follow the commanded wrench with a first-order lag: the closed loop at
// 1 kHz. Returns the loop's energy at the end of each tick once the hand's target holds still (after 0.2 s): the
// grip's motion, the hand's springs to its target and the coupling's springs (ToolProxy's K).
inline std::vector<double> corner_press_energy(const ToolCoupling& coupling, double motor_lag_s, double seconds) {
  // The floor, and a wall whose face is the plane x = 10 mm.
  const PlaneSet planes =
      set_of({floor_plane(0), box_object(1, Eigen::Vector3d(0.06, 0, 0.05), Eigen::Vector3d(0.05, 0.05, 0.05))});
  ToolProxy proxy(cube_tool(), coupling);
  const GripHandParams hand_params;
  const BodyPose start = pose_at(Eigen::Vector3d(0.0, 0.0, 0.02));
  GripHand hand(hand_params, GripPose{start.position_m, start.orientation});
  // 5 mm into the floor and 3 mm into the wall (the cube touches both with its centre at z = 10 mm and x = 0), turned
  // 0.1 rad about an oblique axis.
  const GripPose target{Eigen::Vector3d(0.003, 0.0, 0.005), turn_quaternion(Eigen::Vector3d(0.05, 0.08, 0.03))};
  constexpr int kSubsteps = 10;
  const double h_s = kToolTick_s / kSubsteps;
  GripWrench applied = GripWrench::Zero();
  std::vector<double> energy_J;
  for (int tick = 0; tick < static_cast<int>(seconds / kToolTick_s); ++tick) {
    const double s = std::min(1.0, tick * kToolTick_s / 0.2);
    const GripPose aim{start.position_m + s * (target.position_m - start.position_m),
                       Eigen::Quaterniond::Identity().slerp(s, target.orientation)};
    const GripPose now = hand.pose();
    const ToolResult& result = proxy.solve(planes, BodyPose{now.position_m, now.orientation}, kToolTick_s);
    GripWrench commanded;
    commanded << result.force_N, result.torque_Nm;
    for (int k = 0; k < kSubsteps; ++k) {
      applied += (commanded - applied) * (motor_lag_s > 0.0 ? 1.0 - std::exp(-h_s / motor_lag_s) : 1.0);
      hand.step(aim, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), applied, h_s);
    }
    if (s < 1.0) continue;
    const GripPose grip = hand.pose();
    const Eigen::Vector3d spring_m = result.proxy.position_m - grip.position_m;
    const Eigen::Vector3d spring_rad = turn_between(grip.orientation, result.proxy.orientation);
    const double kinetic_J = 0.5 * hand_params.mass_kg * hand.velocity_mps().squaredNorm() +
                             0.5 * hand_params.inertia_kgm2 * hand.angular_velocity_radps().squaredNorm();
    const double hand_J = 0.5 * hand_params.stiffness_Npm * (aim.position_m - grip.position_m).squaredNorm() +
                          0.5 * hand_params.rotational_stiffness_Nmprad *
                              turn_between(grip.orientation, aim.orientation).squaredNorm();
    const double coupling_J = 0.5 * coupling.stiffness_Npm * spring_m.squaredNorm() +
                              0.5 * coupling.rotational_stiffness_Nmprad * spring_rad.squaredNorm();
    energy_J.push_back(kinetic_J + hand_J + coupling_J);
  }
  return energy_J;
}

// Sixteen objects within 7 cm of the origin, static, some turned: the planes the servo would carry for them.
inline PlaneSet clutter() {
  PlaneSet set;
  set.planes[set.count++] = floor_plane(0);
  set.planes[0].point_m = Eigen::Vector3d(0.0, 0.0, -0.06);
  for (int k = 1; k < 16; ++k) {
    const double a = 2.399963 * k;  // golden-angle spiral
    const double z = 1.0 - 2.0 * (k + 0.5) / 16.0;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d centre_m = (0.045 + 0.01 * (k % 3)) * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z);
    const Eigen::Matrix3d axes = turn_quaternion(Eigen::Vector3d(0.3 * k, 0.7 * k, 0.1 * k)).toRotationMatrix();
    ContactPlane plane = box_object(k, centre_m, Eigen::Vector3d(0.012, 0.008, 0.01), false, axes);
    if (k % 4 == 1) plane.shape = round_shape(ShapeKind::sphere, 0.012);
    if (k % 4 == 2) plane.shape = round_shape(ShapeKind::capsule, 0.006, 0.02);
    if (k == 7) plane.shape = round_shape(ShapeKind::cylinder, 0.01, 0.015);
    if (plane.shape.kind == ShapeKind::sphere) {
      plane.point_m = centre_m + 0.012 * Eigen::Vector3d::UnitZ();
      plane.normal = Eigen::Vector3d::UnitZ();
    }
    set.planes[set.count++] = plane;
  }
  return set;
}

// The hand's target in a wander through the clutter: within 4 cm of `offset_m`, turning up to 0.6 rad about a wandering axis; the hand
// (common/hand/grip_hand.h) holds the grip and feels the rendered wrench, so the grip stops at surfaces as a user's
// would, a few millimetres in.
inline GripPose wander_target(int tick, const Eigen::Vector3d& offset_m) {
  const double t = tick * 1e-3;
  const BodyPose pose =
      pose_at(offset_m + 0.04 * Eigen::Vector3d(std::sin(3.1 * t), std::sin(2.3 * t + 1.0), std::sin(1.7 * t)),
              0.6 * Eigen::Vector3d(std::sin(1.3 * t), std::sin(0.9 * t + 2.0), std::sin(0.7 * t + 1.0)));
  return {pose.position_m, pose.orientation};
}

// A probe: a capsule of 3 mm radius, 6 cm between its cap centres, its middle 2 cm below the grip.
inline ToolShape probe_tool() {
  return {round_shape(ShapeKind::capsule, 0.003, 0.06),
          BodyPose{Eigen::Vector3d(0.0, 0.0, -0.02), Eigen::Quaterniond::Identity()}};
}

// Plays the hand (common/hand/grip_hand.h, defaults) holding the tool's grip against the wander's target for `ticks`
// ticks of 1 ms, the proxy's wrench on the grip held over each tick's ten sub-steps: before(), then the solve, then
// after(tick, grip, result).
template <typename Before, typename After>
void wander(ToolProxy& proxy, const PlaneSet& planes, const Eigen::Vector3d& offset_m, int ticks, Before&& before,
            After&& after) {
  GripHand hand(GripHandParams{}, wander_target(0, offset_m));
  for (int tick = 0; tick < ticks; ++tick) {
    const GripPose now = hand.pose();
    const BodyPose grip{now.position_m, now.orientation};
    before();
    const ToolResult& result = proxy.solve(planes, grip, kToolTick_s);
    after(tick, grip, result);
    GripWrench wrench;
    wrench << result.force_N, result.torque_Nm;
    for (int k = 0; k < 10; ++k) {
      hand.step(wander_target(tick, offset_m), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), wrench,
                kToolTick_s / 10);
    }
  }
}

}  // namespace impetus::test
