// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mesh_check.h"

#include "common/runtime/input_error.h"
#include "common/runtime/message_text.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace impetus {
namespace {

// One use of an edge by a triangle: the edge's vertices in ascending order, which triangle, and whether the triangle
// runs it from the lower vertex to the higher.
struct EdgeUse {
  std::uint32_t low, high, triangle;
  bool forward;
};

}  // namespace

MeshReport check_mesh(const TriangleMesh& mesh) {
  MeshReport report;
  report.triangles = mesh.triangles.size();
  std::vector<EdgeUse> uses;
  uses.reserve(3 * mesh.triangles.size());
  double six_volume = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices_m[tri[0]];
    const Eigen::Vector3d& b = mesh.vertices_m[tri[1]];
    const Eigen::Vector3d& c = mesh.vertices_m[tri[2]];
    const double area_m2 = 0.5 * (b - a).cross(c - a).norm();
    if (!(area_m2 >= kMinTriangleArea_m2) || tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      if (report.first_degenerate < 0) report.first_degenerate = static_cast<std::int64_t>(t);
      ++report.degenerate_triangles;
    }
    six_volume += a.dot(b.cross(c));
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t from = tri[e], to = tri[(e + 1) % 3];
      uses.push_back({std::min(from, to), std::max(from, to), static_cast<std::uint32_t>(t), from < to});
    }
  }
  report.signed_volume_m3 = six_volume / 6.0;
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.low != y.low ? x.low < y.low : x.high != y.high ? x.high < y.high : x.triangle < y.triangle;
  });
  const auto note = [](std::int64_t& first, std::uint32_t triangle) {
    if (first < 0 || triangle < first) first = triangle;
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].low == uses[i].low && uses[j].high == uses[i].high) ++j;
    const std::size_t count = j - i;
    if (count == 1) {
      ++report.open_edges;
      note(report.first_open, uses[i].triangle);
    } else if (count > 2) {
      ++report.nonmanifold_edges;
      note(report.first_nonmanifold, uses[i].triangle);
    } else if (uses[i].forward == uses[i + 1].forward) {
      ++report.misoriented_edges;
      note(report.first_misoriented, uses[i + 1].triangle);
    }
    i = j;
  }
  return report;
}

void flip_winding(TriangleMesh& mesh) {
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}

MeshReport require_usable(TriangleMesh& mesh, bool dynamic, const std::string& source, bool& flipped) {
  flipped = false;
  MeshReport report = check_mesh(mesh);
  const auto fail = [&](std::int64_t triangle, const std::string& what) {
    throw InputError(source + ": triangle " + std::to_string(triangle + 1) + " of " +
                     std::to_string(report.triangles) + " " + what);
  };
  if (report.degenerate_triangles > 0) {
    fail(report.first_degenerate, "has no area (" + std::to_string(report.degenerate_triangles) +
                                      " such triangles; below 1e-18 m², a normal cannot be taken from it)");
  }
  if (!dynamic) return report;
  const std::string reason = " (a body that moves needs a closed surface to have a volume, a mass and an inside)";
  if (report.open_edges > 0) {
    fail(report.first_open, "has an open edge: " + std::to_string(report.open_edges) + " edges belong to one "
                            "triangle only" + reason);
  }
  if (report.nonmanifold_edges > 0) {
    fail(report.first_nonmanifold, "shares an edge with two or more others: " +
                                       std::to_string(report.nonmanifold_edges) + " such edges" + reason);
  }
  if (report.misoriented_edges > 0) {
    fail(report.first_misoriented, "is wound against its neighbour: " + std::to_string(report.misoriented_edges) +
                                       " edges run the same way in both their triangles (some faces point in)");
  }
  // The volume relative to the mesh's size: a closed surface folded flat encloses nothing.
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices_m) box.extend(v);
  const double extent_m = box.sizes().maxCoeff();
  if (!(std::abs(report.signed_volume_m3) > 1e-9 * extent_m * extent_m * extent_m)) {
    throw InputError(source + ": encloses no volume (" + readable(report.signed_volume_m3) +
                     " m³): a body that moves needs one");
  }
  if (report.signed_volume_m3 < 0.0) {
    flip_winding(mesh);
    report.signed_volume_m3 = -report.signed_volume_m3;
    flipped = true;
  }
  return report;
}

}  // namespace impetus
