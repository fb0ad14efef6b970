// SPDX-License-Identifier: Apache-2.0
#include "viewer/mesh_coarsening.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace impetus::view {
namespace {

// One clustering on cells of `cell_m` from `origin_m`.
TriangleMesh cluster(const TriangleMesh& mesh, const Eigen::Vector3d& origin_m, double cell_m) {
  // A cell by its three indices packed into 21 bits each: over 2·10^6 cells an axis, more than any cell size tried
  // here needs (the first is the box's diagonal over √max, so an axis has at most about √max cells).
  const auto key_of = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d index = ((v - origin_m) / cell_m).array().floor();
    return (static_cast<std::uint64_t>(index.x()) << 42) | (static_cast<std::uint64_t>(index.y()) << 21) |
           static_cast<std::uint64_t>(index.z());
  };
  std::unordered_map<std::uint64_t, std::uint32_t> cell_of;
  std::vector<Eigen::Vector3d> sum;
  std::vector<double> count;
  std::vector<std::uint32_t> merged(mesh.vertices_m.size());
  for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v) {
    const auto [it, added] = cell_of.try_emplace(key_of(mesh.vertices_m[v]), static_cast<std::uint32_t>(sum.size()));
    if (added) {
      sum.push_back(Eigen::Vector3d::Zero());
      count.push_back(0.0);
    }
    merged[v] = it->second;
    sum[it->second] += mesh.vertices_m[v];
    count[it->second] += 1.0;
  }
  TriangleMesh out;
  out.vertices_m.resize(sum.size());
  for (std::size_t c = 0; c < sum.size(); ++c) out.vertices_m[c] = sum[c] / count[c];
  // A kept triangle once: by its cells turned so the least comes first (the winding kept).
  struct Hash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& cells) const {
      return static_cast<std::size_t>((std::uint64_t{cells[0]} * 0x9e3779b97f4a7c15ull) ^
                                      (std::uint64_t{cells[1]} * 0xc2b2ae3d27d4eb4full) ^ std::uint64_t{cells[2]});
    }
  };
  std::unordered_set<std::array<std::uint32_t, 3>, Hash> seen;
  for (const auto& tri : mesh.triangles) {
    std::array<std::uint32_t, 3> cells{merged[tri[0]], merged[tri[1]], merged[tri[2]]};
    if (cells[0] == cells[1] || cells[1] == cells[2] || cells[2] == cells[0]) continue;
    std::rotate(cells.begin(), std::min_element(cells.begin(), cells.end()), cells.end());
    if (!seen.insert(cells).second) continue;
    out.triangles.push_back(cells);
  }
  return out;
}

}  // namespace

CoarseMesh coarsened(const TriangleMesh& mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles || max_triangles == 0) return {mesh, 0.0};
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices_m) box.extend(v);
  const double diagonal_m = std::max(box.diagonal().norm(), 1e-9);
  double cell_m = diagonal_m / std::sqrt(static_cast<double>(max_triangles));
  for (;;) {
    TriangleMesh out = cluster(mesh, box.min(), cell_m);
    if (out.triangles.size() <= max_triangles) return {std::move(out), cell_m};
    cell_m *= 1.25;
  }
}

}  // namespace impetus::view
