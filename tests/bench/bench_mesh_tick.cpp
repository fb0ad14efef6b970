// SPDX-License-Identifier: Apache-2.0
// The haptic servo's tick with one body in reach (docs/meshes.md): a ball of 5 cm radius as the primitive sphere and as
// icosphere meshes of 1 280 to 1.3 million triangles, whose triangles the proxy walks (haptic_controller/mesh_walk.h),
// and the primitive box beside them. The finger presses 3 mm in and slides around the ball's top (a circle of 2 cm
// radius, 6 cm/s); the world's plane is renewed every 50 ticks (20 Hz) at the proxy's nearest point. Times the servo's
// tick alone (planes, god-object, force, accumulation; no device): p50, p99 and max in ns, over 20 000 ticks a body.
// Also each mesh's load and build time. Prints only; asserts nothing. --help for the options.

#include "common/mesh/mesh_body.h"
#include "haptic_controller/servo.h"
#include "tests/support/mesh_shapes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

using namespace impetus;

namespace {

int g_ticks = 20000;  // --ticks
constexpr int kTicksPerWorldStep = 50;
constexpr double kRadius_m = 0.05;
const Eigen::Vector3d kCentre_m(0.0, 0.0, 0.0);

// The finger at tick `tick`: it comes down onto the ball over the first 200 ticks (a finger that starts inside a body
// is not pushed out: haptic_controller/god_object.h), then stays 3 mm inside its surface, circling its top.
Eigen::Vector3d finger_at(int tick) {
  const double angle = tick * 1e-3 * 3.0;  // rad: 6 cm/s on a 2 cm circle
  const Eigen::Vector3d direction = Eigen::Vector3d(0.02 * std::cos(angle), 0.02 * std::sin(angle), kRadius_m)
                                        .normalized();
  const double depth_m = tick < 200 ? 0.005 - 0.008 * tick / 200.0 : -0.003;
  return kCentre_m + (kRadius_m + depth_m) * direction;
}

PlaneFrame frame_for(const Shape& shape, const Eigen::Vector3d& proxy_m, std::uint64_t index) {
  PlaneFrame frame;
  frame.frame_index = index;
  frame.world_session = 1;
  frame.world_period_s = kTicksPerWorldStep * 1e-3;
  frame.stiffness_Npm = 2000.0;
  const SurfacePoint surface = nearest_surface_point(shape, BodyPose{kCentre_m, Eigen::Quaterniond::Identity()},
                                                     proxy_m);
  Plane& plane = frame.planes[frame.plane_count++];
  plane.object_id = 0;
  plane.point_m = to_vec3(surface.point_m);
  plane.normal = to_vec3(surface.normal);
  plane.com_m = to_vec3(kCentre_m);
  plane.static_friction = 0.3;
  plane.dynamic_friction = 0.2;
  plane.extent_m = plane_extent_m(shape);
  plane.shape = shape;
  if (traits(shape.kind).carries_axes) {
    plane.body_axis_x = {1.0, 0.0, 0.0};
    plane.body_axis_y = {0.0, 1.0, 0.0};
  }
  return frame;
}

void run(const std::string& name, const Shape& shape) {
  HapticServo servo(ServoOptions{}, 1);
  std::vector<double> ns;  // after the approach's 200 ticks
  ns.reserve(static_cast<std::size_t>(g_ticks));
  int contact_ticks = 0;
  Eigen::Vector3d proxy_m = finger_at(0);
  for (int tick = 0; tick < g_ticks; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % kTicksPerWorldStep == 0) servo.on_plane_frame(frame_for(shape, proxy_m, tick / 50), now_s);
    FingerSample finger;
    finger.position_m = finger_at(tick);
    finger.valid = true;
    const auto start = std::chrono::steady_clock::now();
    const TickResult& result = servo.tick(&finger, now_s, 1e-3);
    const auto stop = std::chrono::steady_clock::now();
    if (tick >= 200) ns.push_back(std::chrono::duration<double, std::nano>(stop - start).count());
    proxy_m = to_eigen(result.proxy_m);
    contact_ticks += result.active_planes > 0 ? 1 : 0;
  }
  std::sort(ns.begin(), ns.end());
  const std::size_t n = ns.size();
  std::printf("%-34s tick p50 %7.0f ns  p99 %7.0f ns  max %8.0f ns  (contact ticks %.0f%%)\n", name.c_str(),
              ns[n / 2], ns[n * 99 / 100], ns.back(), 100.0 * contact_ticks / g_ticks);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {3, 5, 6, 8};  // icosphere subdivisions: 1 280, 20 480, 81 920, 1 310 720 triangles
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--ticks" && k + 1 < argc && std::atoi(argv[k + 1]) > 400) {
      g_ticks = std::atoi(argv[++k]);
    } else if (arg == "--subdivisions" && k + 1 < argc && std::atoi(argv[k + 1]) >= 0 && std::atoi(argv[k + 1]) <= 8) {
      sizes = {std::atoi(argv[++k])};
    } else {
      std::FILE* to = arg == "--help" || arg == "-h" ? stdout : stderr;
      std::fprintf(to,
                   "usage: bench_mesh_tick [--ticks N] [--subdivisions S]\n"
                   "  --ticks N         ticks a body, more than 400 (the first 200 press in; default 20000)\n"
                   "  --subdivisions S  only the icosphere of 20*4^S triangles, S in 0..8 (default: S = 3, 5, 6, 8)\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  Shape box;
  box.kind = ShapeKind::box;
  box.box_size_m = {2 * kRadius_m, 2 * kRadius_m, 2 * kRadius_m};
  run("primitive box (its top face)", box);
  Shape sphere;
  sphere.kind = ShapeKind::sphere;
  sphere.radius_m = kRadius_m;
  run("primitive sphere", sphere);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "impetus-bench-mesh-tick";
  std::filesystem::create_directories(dir);
  for (const int subdivisions : sizes) {
    const TriangleMesh mesh = test::icosphere(kRadius_m, subdivisions);
    const std::string file = (dir / ("ball" + std::to_string(subdivisions) + ".stl")).string();
    test::write_stl_binary(mesh, file);
    const auto start = std::chrono::steady_clock::now();
    const MeshBody& body = MeshBody::load(file, Eigen::Vector3d::Ones(), false);
    const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("mesh of %zu triangles: read, checked and built in %.2f s\n", mesh.triangles.size(), load_s);
    run("mesh ball, " + std::to_string(mesh.triangles.size()) + " triangles", body.shape());
  }
  return 0;
}
