// SPDX-License-Identifier: Apache-2.0
// A deformable slab's cost (docs/deformation.md), on both sides of the link:
//   world:  one world step's denting of a 128 × 128-cell slab (12.8 cm at 1 mm): a 5 mm stroke of push laid along
//           its path and over the pad, then the law over the touched cells; and the penetration rule's step;
//   haptic: the servo's tick with a finger pressing 3 mm into the slab's face and circling (2 cm radius, 6 cm/s), the
//           face as a deformable plane taken again from the frame's heights every tick and yielding between frames,
//           beside the same face as a rigid box's plane. The
//           world's frame comes every 50 ticks (20 Hz) and has applied the reports up to the tick before it; and the
//           worst case of a world that never applies any (every push since the start pending, up to the record's
//           capacity).
//   gel:    the elastic slab of scenes/gel.json over the same cells: a world step's substeps, and its frame's patch.
// p50, p99 and max in ns. Prints only; asserts nothing.

#include "haptic_controller/servo.h"
#include "world_manager/deform/deformable_surface.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace impetus;

namespace {

constexpr int kTicks = 20000;
constexpr int kTicksPerWorldStep = 50;
constexpr double kTop_m = 0.03;

void print(const std::string& name, std::vector<double> ns) {
  std::sort(ns.begin(), ns.end());
  const std::size_t n = ns.size();
  std::printf("%-58s p50 %8.0f ns  p99 %8.0f ns  max %9.0f ns\n", name.c_str(), ns[n / 2], ns[n * 99 / 100], ns.back());
}

void world_steps() {
  DeformableMaterial clay;
  const Eigen::Vector3d half_m(0.064, 0.064, 0.015);
  DeformableSurface surface(clay, half_m, Eigen::Vector3d(0, 0, 0.015), Eigen::Quaterniond::Identity());
  std::printf("slab: %zu × %zu cells\n", surface.columns(), surface.rows());
  std::vector<double> ns;
  for (int step = 0; step < 2000; ++step) {
    // A stroke circling the face's centre, 5 mm per step (10 cm/s at 20 Hz), 50 mN·s beyond yield per step.
    const double angle = 0.125 * step;
    const Eigen::Vector3d from_m(0.04 * std::cos(angle), 0.04 * std::sin(angle), kTop_m);
    const Eigen::Vector3d to_m(0.04 * std::cos(angle + 0.125), 0.04 * std::sin(angle + 0.125), kTop_m);
    const auto start = std::chrono::steady_clock::now();
    surface.press({0.05, from_m, to_m});
    surface.yield_period();
    ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count());
  }
  print("world step, impulse rule (a 5 mm stroke laid and yielded)", ns);
  clay.rule = DeformableMaterial::Rule::penetration;
  DeformableSurface penetrated(clay, half_m, Eigen::Vector3d(0, 0, 0.015), Eigen::Quaterniond::Identity());
  ns.clear();
  for (int step = 0; step < 2000; ++step) {
    const double angle = 0.125 * step;
    const double x_m = 0.04 * std::cos(angle);
    const double y_m = 0.04 * std::sin(angle);
    // 10 µm below the surface there (its height in the body frame, whose centre is 15 mm up).
    const Eigen::Vector3d finger_m(x_m, y_m, 0.015 + penetrated.height_m(x_m, y_m) - 1e-5);
    const auto start = std::chrono::steady_clock::now();
    penetrated.press_by_penetration(finger_m);
    ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count());
  }
  print("world step, penetration rule (one sampled finger)", ns);
}

// The gel of scenes/gel.json over the same 128 × 128 cells: a world step (its substeps of the membrane) under a press
// circling as above, at 20 and 10 Hz, and the frame's patch (the heights less the finger's own static response).
void elastic_steps() {
  DeformableMaterial gel;
  gel.law = DeformableMaterial::Law::elastic;
  const Eigen::Vector3d half_m(0.064, 0.064, 0.015);
  for (const double rate_hz : {20.0, 10.0}) {
    DeformableSurface surface(gel, half_m, Eigen::Vector3d(0, 0, 0.015), Eigen::Quaterniond::Identity());
    const double period_s = 1.0 / rate_hz;
    std::vector<double> ns, patch_ns;
    DentPatch patch;
    for (int step = 0; step < 200; ++step) {
      const double angle = 0.125 * step;
      const Eigen::Vector3d from_m(0.04 * std::cos(angle), 0.04 * std::sin(angle), kTop_m);
      const Eigen::Vector3d to_m(0.04 * std::cos(angle + 0.125), 0.04 * std::sin(angle + 0.125), kTop_m);
      const auto start = std::chrono::steady_clock::now();
      surface.press({1.0 * period_s, from_m, to_m});  // 1 N
      surface.yield_period(period_s);
      const auto stepped = std::chrono::steady_clock::now();
      surface.patch_about(surface.to_body(to_m), 0, 0.0, patch, 0);
      ns.push_back(std::chrono::duration<double, std::nano>(stepped - start).count());
      patch_ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - stepped).count());
    }
    const std::string rate = std::to_string(static_cast<int>(rate_hz)) + " Hz";
    print("world step, gel at " + rate + " (1 N circling, all substeps)", ns);
    print("frame patch, gel at " + rate + " (less the finger's response)", patch_ns);
  }
}

Eigen::Vector3d finger_at(int tick) {
  const double angle = tick * 1e-3 * 3.0;
  const double depth_m = tick < 200 ? 0.005 - 0.008 * tick / 200.0 : -0.003;
  return {0.02 * std::cos(angle), 0.02 * std::sin(angle), kTop_m + depth_m};
}

PlaneFrame frame_at(const Eigen::Vector3d& proxy_m, std::uint64_t index, std::uint64_t applied_tick, bool deformable) {
  PlaneFrame frame;
  frame.frame_index = index;
  frame.world_session = 1;
  frame.world_period_s = kTicksPerWorldStep * 1e-3;
  frame.stiffness_Npm = 2000.0;
  frame.report_session_applied = applied_tick > 0 ? 1 : 0;
  frame.report_tick_applied = applied_tick;
  Plane& plane = frame.planes[frame.plane_count++];
  plane.object_id = 0;
  plane.point_m = {proxy_m.x(), proxy_m.y(), kTop_m};
  plane.normal = {0.0, 0.0, 1.0};
  plane.com_m = {0.0, 0.0, 0.015};
  plane.static_friction = 0.6;
  plane.dynamic_friction = 0.5;
  if (deformable) {
    const DeformableMaterial clay;
    plane.flags = kPlaneDeformable;
    plane.extent_m = clay.contact_radius_m;
    plane.yield_force_N = clay.yield_force_N();
    plane.yield_depth_mpNs = clay.yield_depth_mpNs();
    plane.yield_radius_m = clay.contact_radius_m;
    plane.yield_room_m = 0.027;
    // The heights around the proxy the world sends with it (a flat face here: the cost is the same).
    DentPatch& patch = frame.dent_patch;
    patch.object_id = 0;
    patch.origin_m = {proxy_m.x() - 0.0075, proxy_m.y() - 0.0075, 0.0};
    patch.axis_x = {1.0, 0.0, 0.0};
    patch.axis_y = {0.0, 1.0, 0.0};
    patch.spacing_m = 0.001;
    patch.height_m.fill(kTop_m);
  } else {
    plane.shape.kind = ShapeKind::box;
    plane.shape.box_size_m = {0.2, 0.2, 0.03};
    plane.extent_m = plane_extent_m(plane.shape);
    plane.body_axis_x = {1.0, 0.0, 0.0};
    plane.body_axis_y = {0.0, 1.0, 0.0};
  }
  return frame;
}

void haptic_ticks(const std::string& name, bool deformable, bool world_applies) {
  HapticServo servo(ServoOptions{}, 1);
  std::vector<double> ns;
  Eigen::Vector3d proxy_m = finger_at(0);
  for (int tick = 0; tick < kTicks; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % kTicksPerWorldStep == 0) {
      const std::uint64_t applied = world_applies && tick > 0 ? static_cast<std::uint64_t>(tick) : 0;
      servo.on_plane_frame(frame_at(proxy_m, static_cast<std::uint64_t>(tick / kTicksPerWorldStep), applied,
                                    deformable),
                           now_s);
    }
    FingerSample finger;
    finger.position_m = finger_at(tick);
    finger.valid = true;
    const auto start = std::chrono::steady_clock::now();
    const TickResult& result = servo.tick(&finger, now_s, 1e-3);
    const auto stop = std::chrono::steady_clock::now();
    if (tick >= 200) ns.push_back(std::chrono::duration<double, std::nano>(stop - start).count());
    proxy_m = to_eigen(result.proxy_m);
  }
  print(name, ns);
}

}  // namespace

int main() {
  world_steps();
  elastic_steps();
  haptic_ticks("haptic tick, the face as a rigid box's plane", false, true);
  haptic_ticks("haptic tick, the face as clay, yielding between frames", true, true);
  haptic_ticks("haptic tick, clay, a world that applies nothing (worst)", true, false);
  return 0;
}
