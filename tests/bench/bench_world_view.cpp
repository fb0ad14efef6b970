// SPDX-License-Identifier: Apache-2.0
// What the world view costs the world manager per step, and a viewer per frame, against the number of bodies: the
// snapshot taken from the world and published into shared memory (the world's cost), read back and encoded for the
// page (the viewer's cost), and the sizes of both. Resting boxes on the floor, as in a cluttered scene; the world
// step beside them for scale. Prints medians; asserts nothing.
//
//   bench_world_view [STEPS=200]

#include "common/link/shm/shm_world_view.h"
#include "common/runtime/loop_stats.h"
#include "viewer/view_encoding.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world.h"
#include "world_manager/world_view.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace impetus;

// `count` 2 cm boxes in a square grid on the floor, every tenth dynamic.
Scene grid_scene(int count) {
  std::string text = R"({"objects": [)";
  const int side = static_cast<int>(std::ceil(std::sqrt(count)));
  for (int k = 0; k < count; ++k) {
    char object[256];
    std::snprintf(object, sizeof object,
                  R"(%s{"name": "b%d", "shape": "box", "size_m": [0.02, 0.02, 0.02], "dynamic": %s, %s"position_m": [%.3f, %.3f, 0.01]})",
                  k ? "," : "", k, k % 10 == 0 ? "true" : "false", k % 10 == 0 ? R"("mass_kg": 0.1, )" : "",
                  (k % side) * 0.03, (k / side) * 0.03);
    text += object;
  }
  return parse_scene_text(text + "]}", "grid");
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 200;
  if (steps < 1) {
    std::fprintf(stderr, "usage: bench_world_view [STEPS>0]\n");
    return 2;
  }
  prepare_engines();
  std::printf("%8s %12s %12s %14s %14s %14s %12s\n", "bodies", "step us", "snapshot B", "take+pub us",
              "read us", "encode us", "message B");
  for (const int count : {2, 100, 500, 2000}) {
    const Scene scene = grid_scene(count);
    World world(scene, WorldOptions{});
    const std::string shm = "impetus_bench_view_" + std::to_string(getpid()) + "_" + std::to_string(count);
    ShmWorldViewPublisher publisher(shm);
    ShmWorldViewReader reader(shm);
    auto snapshot = std::make_unique<WorldSnapshot>();
    auto read = std::make_unique<WorldSnapshot>();
    HapticReport report{};
    report.finger_valid = 1;
    report.finger_m = {0.0, 0.0, 0.05};
    report.proxy_m = report.finger_m;
    std::string message;
    std::vector<double> step_us, publish_us, read_us, encode_us;
    for (int i = 0; i < steps; ++i) {
      std::int64_t t0 = thread_cpu_now_ns();
      world.step(&report);
      std::int64_t t1 = thread_cpu_now_ns();
      take_snapshot(world, &report, LoopStats{}, nullptr, *snapshot);
      publisher.publish_snapshot(*snapshot);
      std::int64_t t2 = thread_cpu_now_ns();
      if (!reader.read_snapshot(*read)) {
        std::fprintf(stderr, "bench_world_view: a snapshot was not read back\n");
        return 1;
      }
      std::int64_t t3 = thread_cpu_now_ns();
      view::encode_frame(*read, true, 1.0, message);
      std::int64_t t4 = thread_cpu_now_ns();
      step_us.push_back((t1 - t0) * 1e-3);
      publish_us.push_back((t2 - t1) * 1e-3);
      read_us.push_back((t3 - t2) * 1e-3);
      encode_us.push_back((t4 - t3) * 1e-3);
    }
    std::printf("%8d %12.1f %12zu %14.2f %14.2f %14.2f %12zu\n", count, median(step_us), snapshot->used_bytes(),
                median(publish_us), median(read_us), median(encode_us), message.size());
  }
  std::printf("(CPU time per world step, medians of %d steps; 'take+pub' is what the world manager pays, 'read' and "
              "'encode' what a viewer pays per frame)\n", steps);
  return 0;
}
