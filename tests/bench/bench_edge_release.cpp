// SPDX-License-Identifier: Apache-2.0
// What the finger feels at a box's edge between world frames, for the figure in docs/results.md
// (scripts/edge_figure.py). A finger pressed 3 mm into the top of a static 5 cm box slides along +x at 0.2 m/s and off
// the +x edge, at the top's depth: beyond the edge it is in free space beside the box. A 20 Hz world sends its planes;
// the servo renders them (a) as the world sent them, a face's plane until the next frame (the shape stripped from each
// plane), and (b) taken again at the proxy every tick (shape_planes.h). The exact god-object: K·depth over the face,
// nothing past it. Prints CSV: time_s, finger_x_m (from the edge), then the upward force in N of (a), (b) and the exact
// one.

#include "haptic_controller/servo.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"

#include <algorithm>
#include <cstdio>

namespace {

using namespace impetus;

constexpr double kHalf_m = 0.025;
constexpr double kDepth_m = 0.003;
constexpr double kSpeed_mps = 0.2;

Scene box_scene() {
  Scene scene;
  scene.source_name = "edge";
  scene.floor.present = false;
  SceneObject box;
  box.name = "box";
  box.dynamic = false;
  box.shape.kind = ShapeKind::box;
  box.shape.box_size_m = {2 * kHalf_m, 2 * kHalf_m, 2 * kHalf_m};
  box.position_m = {0.0, 0.0, 0.0};
  box.material.static_friction = 0.0;  // frictionless: the exact god-object is K·depth, straight up
  box.material.dynamic_friction = 0.0;
  scene.objects.push_back(box);
  return scene;
}

// The finger: 5 mm above the top, 30 mm in from the edge, down to 3 mm deep in the first 50 ms, then along +x from
// t = 55 ms, so it crosses the edge at 205 ms: 5 ms after a 20 Hz frame, early in the period, where the face's plane
// as sent lasts longest (45 ms more).
constexpr double kSlideStart_s = 0.055;
Eigen::Vector3d finger_at(double t_s) {
  const double x_m = kHalf_m - 0.030 + kSpeed_mps * std::max(0.0, t_s - kSlideStart_s);
  const double z_m = kHalf_m + 0.005 - (0.005 + kDepth_m) * std::min(1.0, t_s / 0.05);
  return {x_m, 0.0, z_m};
}

}  // namespace

int main() {
  prepare_engines();
  const Scene scene = box_scene();
  World world(scene, WorldOptions{});
  HapticServo as_sent(ServoOptions{}, 1);
  HapticServo retaken(ServoOptions{}, 2);
  std::printf("time_s,finger_from_edge_m,force_as_sent_N,force_retaken_N,force_exact_N\n");
  const double stiffness_Npm = scene.haptic.stiffness_Npm;
  for (int j = 0; j < 300; ++j) {
    const double t_s = 1e-3 * j;
    if (j % 50 == 0) {
      HapticReport report = retaken.report();
      report.haptic_session = 1;
      const PlaneFrame& frame = world.step(&report);
      PlaneFrame stripped = frame;
      for (std::uint32_t k = 0; k < stripped.plane_count; ++k) stripped.planes[k].shape = Shape{};
      as_sent.on_plane_frame(stripped, t_s);
      retaken.on_plane_frame(frame, t_s);
    }
    FingerSample finger;
    finger.position_m = finger_at(t_s);
    finger.valid = true;
    const double x_m = finger.position_m.x();
    const double sent_N = to_eigen(as_sent.tick(&finger, t_s, 1e-3).force_N).z();
    const double retaken_N = to_eigen(retaken.tick(&finger, t_s, 1e-3).force_N).z();
    const double depth_m = kHalf_m - finger.position_m.z();
    const double exact_N = x_m <= kHalf_m && depth_m > 0.0 ? stiffness_Npm * depth_m : 0.0;
    if (t_s >= kSlideStart_s + 0.05) std::printf("%.4f,%.6f,%.4f,%.4f,%.4f\n", t_s, x_m - kHalf_m, sent_N, retaken_N, exact_N);
  }
  return 0;
}
