// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the finger feels between world frames, scored against the true geometry: a world stepping at 20 or 10 Hz sends
// its planes to a 1 kHz servo (as the in-process loop does, without a device), a finger wanders through clutter of
// boxes, capsules, cylinders and spheres in every orientation (static, or a stream sliding past it), and each tick is
// scored by the finger's and the proxy's signed distances to the objects as they truly are. Frictionless: the exact
// god-object then renders no force wherever its proxy can reach the finger, which it surely can when the finger is
// outside every object and the straight way from the proxy to it is clear (the finger here follows its path whatever
// the force, so it may pass right through an object; a god-object is then still held on the side it came in by, and
// that force is not a ghost).
//   ghost tick      force > 0.1 N while the finger is more than 0.1 mm outside every object and the segment from
//                   the proxy to it clear of them (no point kBlocked_m inside one)
//   contact tick    the finger more than 0.1 mm inside some object
//   lost wall       the finger more than 1 mm inside some object and force < 0.1 N
//   pop-through     the proxy more than 0.5 mm inside some object
//   release         from the finger leaving the last object to the force falling under 0.1 N, in 1 ms ticks

#include "haptic_controller/servo.h"
#include "world_manager/engine/engine_registry.h"
#include "common/shape/shape.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace impetus::test {

inline constexpr double kForce_N = 0.1;       // "some force": 0.05 mm of the 2 kN/m spring
inline constexpr double kOutside_m = 1e-4;    // clearly outside or inside: the spring's 0.2 N
inline constexpr double kDeep_m = 1e-3;       // a wall the exact god-object would push back from with 2 N
inline constexpr double kPopThrough_m = 5e-4;
// A way blocked: the exact god-object is held by any depth of an object across its way, so only rounding is let
// through (the proxy starts on a surface). 1 µm is 2 mN of the spring, far above rounding and below any force scored.
inline constexpr double kBlocked_m = 1e-6;
inline constexpr double kPi = 3.14159265358979323846;

struct Score {
  int ticks = 0;
  int contact_ticks = 0;
  int ghost_ticks = 0;
  int lost_wall_ticks = 0;
  int pop_through_ticks = 0;
  double worst_release_ms = 0.0;
  double ghost_fraction() const { return contact_ticks > 0 ? double(ghost_ticks) / contact_ticks : 0.0; }
};

// `count` static objects of mixed shapes (2–3 cm) in random poses within a 12 cm cube about the origin, floating
// (no floor), frictionless. Seeded: the same clutter every run.
inline Scene clutter(int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Scene scene;
  scene.source_name = "clutter";
  scene.floor.present = false;
  for (int k = 0; k < count; ++k) {
    SceneObject object;
    object.name = "o";  // appended, not "o" + ...: GCC 12 reports a false -Wrestrict on that
    object.name += std::to_string(k);
    object.dynamic = false;
    object.material.static_friction = 0.0;
    object.material.dynamic_friction = 0.0;
    const int kind = k % 4;
    const double size_m = 0.02 + 0.01 * unit(random);
    if (kind == 0) {
      object.shape.kind = ShapeKind::box;
      object.shape.box_size_m = {size_m, 0.7 * size_m + 0.005, 0.5 * size_m + 0.005};
    } else if (kind == 1) {
      object.shape.kind = ShapeKind::capsule;
      object.shape.radius_m = 0.3 * size_m;
      object.shape.length_m = size_m;
    } else if (kind == 2) {
      object.shape.kind = ShapeKind::cylinder;
      object.shape.radius_m = 0.4 * size_m;
      object.shape.length_m = size_m;
    } else {
      object.shape.kind = ShapeKind::sphere;
      object.shape.radius_m = 0.4 * size_m;
    }
    object.mass_kg = 0.1;
    object.position_m = {0.12 * (unit(random) - 0.5), 0.12 * (unit(random) - 0.5), 0.12 * (unit(random) - 0.5)};
    // A uniform random rotation from the seeded generator (Shoemake's three uniforms; Eigen's UnitRandom draws from
    // std::rand, whose state depends on what ran before, so the same seed would not give the same clutter).
    const double u1 = unit(random), u2 = 2.0 * kPi * unit(random), u3 = 2.0 * kPi * unit(random);
    const Eigen::Quaterniond turn(std::sqrt(u1) * std::cos(u3), std::sqrt(1.0 - u1) * std::sin(u2),
                                  std::sqrt(1.0 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
    object.orientation_wxyz = {turn.w(), turn.x(), turn.y(), turn.z()};
    scene.objects.push_back(object);
  }
  return scene;
}

// A finger wandering through the clutter at about 0.2 m/s: a sum of incommensurate sines, never leaving the 12 cm
// cube.
inline Eigen::Vector3d wander(double t_s) {
  return {0.05 * std::sin(2.1 * t_s) + 0.01 * std::sin(7.3 * t_s), 0.05 * std::sin(1.7 * t_s + 1.0),
          0.05 * std::sin(1.3 * t_s + 2.0) + 0.01 * std::cos(5.9 * t_s)};
}

// Signed distance of `point` to the nearest object (negative inside).
inline double nearest_m(const Scene& scene, const std::vector<BodyPose>& poses, const Eigen::Vector3d& point_m) {
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    nearest = std::min(nearest, nearest_surface_point(scene.objects[k].shape, poses[k], point_m).signed_distance_m);
  }
  return nearest;
}

// Whether the segment from `from_m` to `to_m` stays clear of every object (no sample kBlocked_m inside one), sampled
// every 0.25 mm past its first 0.25 mm (the proxy rests on a surface).
inline bool clear_way(const Scene& scene, const std::vector<BodyPose>& poses, const Eigen::Vector3d& from_m,
               const Eigen::Vector3d& to_m) {
  const double length_m = (to_m - from_m).norm();
  for (double s_m = 2.5e-4; s_m < length_m; s_m += 2.5e-4) {
    if (nearest_m(scene, poses, from_m + (s_m / length_m) * (to_m - from_m)) < -kBlocked_m) return false;
  }
  return true;
}

// A stream of `count` objects of the same mixed shapes sliding past the finger: dynamic, without gravity or floor,
// all at the same `velocity_mps` so that none ever meets another, boxes also spinning about their shortest axis at
// `spin_radps` (their largest moment of inertia, about which a free rotation stays put). Heavy: the finger's pushes
// (at most the servo's 10 N clamp) change a 100 kg object's speed by at most 0.1 mm/s a second, so the stream moves
// as it was set going and the truth between world steps is their interpolation. The objects start upstream, spread
// over the length the stream travels in `duration_s` plus the finger's 12 cm cube, at `count` objects per such cube
// on average, with their bounding spheres apart. Seeded.
inline Scene stream(int count, unsigned seed, const Eigen::Vector3d& velocity_mps, double spin_radps,
                    double duration_s) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Scene shapes = clutter(count, seed);
  Scene scene;
  scene.source_name = "stream";
  scene.floor.present = false;
  scene.gravity_mps2 = {0.0, 0.0, 0.0};
  const double speed_mps = velocity_mps.norm();
  const Eigen::Vector3d along = velocity_mps / speed_mps;
  const double length_m = speed_mps * duration_s + 0.12;
  const int total = static_cast<int>(std::ceil(count * length_m / 0.12));
  std::vector<std::pair<Eigen::Vector3d, double>> placed;  // centre, bounding radius
  for (int k = 0; k < total; ++k) {
    SceneObject object = shapes.objects[static_cast<std::size_t>(k % count)];
    char name[16];  // formatted, not appended: GCC 12 reports a false -Wrestrict on appending to a copied string
    std::snprintf(name, sizeof name, "s%d", k);
    object.name = name;
    object.dynamic = true;
    object.mass_kg = 100.0;
    const double radius_m = world_bounds(object.shape, BodyPose{}).sizes().norm() / 2.0;
    // Upstream of the cube along the motion, across the cube's width; up to 100 tries for a free place (the
    // density leaves room: the count's bounding spheres fill about a fifth of the cube at 16).
    for (int attempt = 0; attempt < 100; ++attempt) {
      const Eigen::Vector3d across(0.12 * (unit(random) - 0.5), 0.12 * (unit(random) - 0.5),
                                   0.12 * (unit(random) - 0.5));
      const Eigen::Vector3d centre = across - along * (across.dot(along) + length_m * unit(random) - 0.06);
      const bool free = std::none_of(placed.begin(), placed.end(), [&](const auto& other) {
        return (other.first - centre).norm() < other.second + radius_m;
      });
      if (!free) continue;
      placed.emplace_back(centre, radius_m);
      object.position_m = {centre.x(), centre.y(), centre.z()};
      const Eigen::Quaterniond turn(object.orientation_wxyz[0], object.orientation_wxyz[1],
                                    object.orientation_wxyz[2], object.orientation_wxyz[3]);
      const Eigen::Vector3d spin = object.shape.kind == ShapeKind::box
                                       ? Eigen::Vector3d(spin_radps * (turn * Eigen::Vector3d::UnitZ()))
                                       : Eigen::Vector3d::Zero();
      object.linear_velocity_mps = {velocity_mps.x(), velocity_mps.y(), velocity_mps.z()};
      object.angular_velocity_radps = {spin.x(), spin.y(), spin.z()};
      scene.objects.push_back(object);
      break;
    }
  }
  return scene;
}

// Scores `duration_s` of the wandering finger in `scene` under `coupling`. Static objects are where the scene puts
// them. A dynamic object is truly where the world's states put it, interpolated between steps, at the time the
// coupling says a frame describes:
//   impulse, position  a step taken at tick k·n simulates to (k+1)·n, and the servo interpolates from frame k−1
//                      to frame k over the period after it arrives (§3.2): the world's state at s is the truth at
//                      tick s;
//   local              a step taken at tick k·n replays the ticks the finger rendered since the last one, up to
//                      tick k·n − 1, placing each impulse when it was rendered (world_manager/couplings/
//                      local_coupling.h); its frame is the state at that last tick, which the servo's model carries on
//                      tick by tick: the world's state at (k+1)·n is the truth at tick k·n − 1, and at s + T + 1 tick
//                      the truth at tick s.
// So the ticks are rendered first and scored once the world has simulated the times they need.
inline Score score(Scene scene, double world_rate_hz, double duration_s, Coupling coupling = Coupling::impulse) {
  prepare_engines();
  scene.physics.world_rate_hz = world_rate_hz;
  std::vector<BodyPose> poses;
  for (const SceneObject& object : scene.objects) {
    BodyPose pose;
    pose.position_m = Eigen::Vector3d(object.position_m[0], object.position_m[1], object.position_m[2]);
    pose.orientation = Eigen::Quaterniond(object.orientation_wxyz[0], object.orientation_wxyz[1],
                                          object.orientation_wxyz[2], object.orientation_wxyz[3]);
    poses.push_back(pose);
  }
  WorldOptions options;
  options.coupling = coupling;
  World world(scene, options);
  HapticServo servo(ServoOptions{}, 1);
  const int ticks_per_step = static_cast<int>(std::lround(1000.0 / world_rate_hz));
  const int lead_ticks = coupling == Coupling::local ? ticks_per_step + 1 : 0;  // world time − tick time, in ticks
  const int ticks = static_cast<int>(duration_s * 1000.0);

  // Rendering: the world's states after each step (history[m] at m periods), and per tick the finger, proxy, force.
  std::vector<std::vector<BodyPose>> history{poses};
  struct Rendered {
    Eigen::Vector3d finger_m, proxy_m;
    double force_N;
  };
  std::vector<Rendered> rendered;
  rendered.reserve(static_cast<std::size_t>(ticks));
  for (int j = 0; j < ticks + lead_ticks + ticks_per_step; ++j) {
    const double t_s = 1e-3 * j;
    if (j % ticks_per_step == 0) {
      HapticReport report = servo.report();
      report.haptic_session = 1;
      servo.on_plane_frame(world.step(&report), t_s);
      history.emplace_back(poses);
      for (std::size_t k = 0; k < scene.objects.size(); ++k) history.back()[k] = world.states()[k].pose;
    }
    if (j >= ticks) continue;  // the world simulates on to the last tick's truth
    FingerSample finger;
    finger.position_m = wander(t_s);
    finger.valid = true;
    const TickResult& tick = servo.tick(&finger, t_s, 1e-3);
    rendered.push_back({finger.position_m, to_eigen(tick.proxy_m), to_eigen(tick.force_N).norm()});
  }

  // Scoring against the truth.
  Score result;
  int left_at = -1;  // the tick the finger last left every object, while the force has not yet let go
  for (int j = ticks_per_step; j < ticks; ++j) {  // from the first frame's arrival
    const std::size_t step = static_cast<std::size_t>((j + lead_ticks) / ticks_per_step);
    const double w = double((j + lead_ticks) % ticks_per_step) / ticks_per_step;
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
      if (!scene.objects[k].dynamic) continue;
      const BodyPose& before = history[step][k];
      const BodyPose& after = history[step + 1][k];
      poses[k].position_m = (1.0 - w) * before.position_m + w * after.position_m;
      poses[k].orientation = before.orientation.slerp(w, after.orientation);
    }
    const Rendered& tick = rendered[static_cast<std::size_t>(j)];
    const double finger_m = nearest_m(scene, poses, tick.finger_m);
    const double proxy_m = nearest_m(scene, poses, tick.proxy_m);
    ++result.ticks;
    if (finger_m < -kOutside_m) ++result.contact_ticks;
    const bool free_finger = finger_m > kOutside_m && proxy_m > -kPopThrough_m &&
                             (tick.force_N <= kForce_N || clear_way(scene, poses, tick.proxy_m, tick.finger_m));
    if (free_finger && tick.force_N > kForce_N) ++result.ghost_ticks;
    if (finger_m < -kDeep_m && tick.force_N < kForce_N) ++result.lost_wall_ticks;
    if (proxy_m < -kPopThrough_m) ++result.pop_through_ticks;
    if (free_finger && left_at < 0 && tick.force_N > kForce_N) left_at = j;
    if (!free_finger) left_at = -1;
    if (left_at >= 0 && tick.force_N <= kForce_N) {
      result.worst_release_ms = std::max(result.worst_release_ms, double(j - left_at));  // 1 ms ticks
      left_at = -1;
    }
  }
  return result;
}

}  // namespace impetus::test
