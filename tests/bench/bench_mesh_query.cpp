// SPDX-License-Identifier: Apache-2.0
// What a nearest-point query on a user's mesh costs (common/mesh/mesh_bvh.h), against the mesh's size: a sphere of
// 10³ to 10⁶ triangles, a point sliding over it at 0.1 m/s, one query per 1 kHz tick, from two depths: 3 mm inside
// (where a finger pressing in is) and on the surface (where a god-object's proxy is), each from scratch and started
// from the last tick's answer (MeshBvh::nearest_from). Also the tree's build time and memory per triangle. Prints percentiles; asserts nothing. The query is the heart of a haptic tick against a mesh,
// not the whole tick (docs/meshes.md).
//
//   bench_mesh_query [QUERIES=20000]

#include "common/mesh/mesh_bvh.h"
#include "common/mesh/mesh_check.h"

#include "tests/support/mesh_shapes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  using namespace impetus;
  using Clock = std::chrono::steady_clock;
  const int queries = argc > 1 ? std::max(100, std::atoi(argv[1])) : 20000;
  const double radius_m = 0.05;
  std::printf("nearest point on a mesh sphere (r = 5 cm), sliding 0.1 m/s, %d queries per row\n", queries);
  std::printf("%10s %8s %6s %10s %12s %10s %10s %10s %10s\n", "triangles", "depth_mm", "hint", "build_ms",
              "bytes/tri", "nodes", "p50_ns", "p99_ns", "max_ns");
  for (const int subdivisions : {3, 5, 6, 8}) {
    TriangleMesh mesh = test::icosphere(radius_m, subdivisions);
    const std::size_t triangles = mesh.triangles.size();
    const auto built = Clock::now();
    const MeshBvh tree(std::move(mesh));
    const double build_ms = std::chrono::duration<double, std::milli>(Clock::now() - built).count();
    for (const double depth_m : {0.003, 0.0}) {
    for (const bool hinted : {false, true}) {
      std::vector<double> ns;
      ns.reserve(static_cast<std::size_t>(queries));
      MeshPoint point, last;
      tree.nearest(Eigen::Vector3d(radius_m, 0.0, 0.0), last);
      double checksum = 0.0;
      for (int q = 0; q < queries; ++q) {
        // A path over the sphere at 0.1 m/s, 1 ms a step: 0.1 mm between queries.
        const double r = radius_m - depth_m;
        const double s = q * 1e-4 / r;
        const Eigen::Vector3d at(r * std::cos(s) * std::cos(0.3 * s), r * std::sin(s) * std::cos(0.3 * s),
                                 r * std::sin(0.3 * s));
        const auto start = Clock::now();
        if (hinted) {
          tree.nearest_from(at, last, point);
        } else {
          tree.nearest(at, point);
        }
        ns.push_back(std::chrono::duration<double, std::nano>(Clock::now() - start).count());
        last = point;
        checksum += point.signed_distance_m;
      }
      if (!std::isfinite(checksum)) return 1;
      std::sort(ns.begin(), ns.end());
      const auto percentile = [&](double f) {
        return ns[std::min(ns.size() - 1, static_cast<std::size_t>(f * static_cast<double>(ns.size())))];
      };
      std::printf("%10zu %8.0f %6s %10.1f %12.0f %10zu %10.0f %10.0f %10.0f\n", triangles, depth_m * 1e3,
                  hinted ? "last" : "none", build_ms,
                  static_cast<double>(tree.memory_bytes()) / static_cast<double>(triangles), tree.node_count(),
                  percentile(0.5), percentile(0.99), ns.back());
    }
    }
  }
  return 0;
}
