// SPDX-License-Identifier: Apache-2.0
#pragma once
// Meshes of known shape for the mesh tests and benchmarks: a box, a subdivided icosahedron (a sphere of 20·4ⁿ
// triangles), writers of the file formats users bring (OBJ, ASCII and binary STL), and the brute-force distance the
// tree is checked against.

#include "common/mesh/mesh_bvh.h"
#include "common/mesh/triangle_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <utility>

namespace impetus::test {

// A box of `size_m` centred on `centre_m`, wound outward.
inline TriangleMesh box_mesh(const Eigen::Vector3d& size_m, const Eigen::Vector3d& centre_m = Eigen::Vector3d::Zero()) {
  TriangleMesh mesh;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5, (k & 4) ? 0.5 : -0.5);
    mesh.vertices_m.push_back(centre_m + corner.cwiseProduct(size_m));
  }
  // Two triangles per face, counter-clockwise seen from outside.
  mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return mesh;
}

// A sphere of `radius_m`: an icosahedron whose faces are split in four `subdivisions` times, the new vertices pushed
// out to the sphere. 20·4ⁿ triangles, wound outward.
inline TriangleMesh icosphere(double radius_m, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh mesh;
  const double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (const auto& v : base) mesh.vertices_m.push_back(Eigen::Vector3d(v[0], v[1], v[2]).normalized() * radius_m);
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
    const auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      const auto index = static_cast<std::uint32_t>(mesh.vertices_m.size());
      mesh.vertices_m.push_back((mesh.vertices_m[a] + mesh.vertices_m[b]).normalized() * radius_m);
      middle.emplace(key, index);
      return index;
    };
    HugeVector<std::array<std::uint32_t, 3>> finer;
    finer.reserve(4 * mesh.triangles.size());
    for (const auto& tri : mesh.triangles) {
      const std::uint32_t ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      finer.push_back({tri[0], ab, ca});
      finer.push_back({tri[1], bc, ab});
      finer.push_back({tri[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(finer);
  }
  return mesh;
}

inline void write_obj(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out(path);
  out.precision(17);
  for (const Eigen::Vector3d& v : mesh.vertices_m) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

inline void write_stl_ascii(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out(path);
  out.precision(9);
  out << "solid test\n";
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d n = (mesh.vertices_m[t[1]] - mesh.vertices_m[t[0]])
                                  .cross(mesh.vertices_m[t[2]] - mesh.vertices_m[t[0]]).normalized();
    out << " facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n  outer loop\n";
    for (std::uint32_t v : t) {
      out << "   vertex " << mesh.vertices_m[v].x() << ' ' << mesh.vertices_m[v].y() << ' ' << mesh.vertices_m[v].z()
          << '\n';
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid test\n";
}

inline void write_stl_binary(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = "binary STL written by the mesh tests";
  out.write(header, sizeof header);
  const auto count = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : mesh.triangles) {
    float values[12] = {};
    for (int k = 0; k < 3; ++k) {
      for (int a = 0; a < 3; ++a) values[3 + 3 * k + a] = static_cast<float>(mesh.vertices_m[t[k]][a]);
    }
    out.write(reinterpret_cast<const char*>(values), sizeof values);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
}

// The distance from `p` to the mesh's nearest point, by trying every triangle.
inline double brute_force_distance(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    std::uint8_t feature = 0;
    const Eigen::Vector3d c =
        closest_point_on_triangle(p, mesh.vertices_m[t[0]], mesh.vertices_m[t[1]], mesh.vertices_m[t[2]], feature);
    best = std::min(best, (p - c).norm());
  }
  return best;
}

}  // namespace impetus::test
