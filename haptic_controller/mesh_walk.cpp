// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/mesh_walk.h"

#include "haptic_controller/gram_solve.h"
#include "haptic_controller/proxy_projection.h"  // kMaxActiveConstraints

#include <bit>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// A step slides the proxy to the next triangle on its way or ends the walk. Along a finely tessellated concave surface
// a proxy crosses one triangle a step; 16 is 16 triangles in one tick, a slide of several centimetres over the
// shipped bowl (more than a finger moves in a tick). A walk that has not ended by then stops at its last triangle.
constexpr int kMaxSteps = 16;
// Two planes whose Gram determinant (sin² of the angle between their normals) is below this are one plane: 1e-12 is
// normals a micro-radian apart, far below any crease a mesh is built with, far above rounding.
constexpr double kParallelGram = 1e-12;

// The point nearest `goal` in front of every plane the walk has met: min |y − goal|² subject to n_i·(y − p_i) ≥ 0.
// The answer holds at most three of the planes as equalities, y = goal + Σ λ_i n_i with every λ_i ≥ 0, and is in
// front of the others; with four planes at most there are fifteen such sets to try, and the nearest point in front
// of all wins. Returns the planes it holds as bits of `held_out`. None (planes that face each other across the way):
// `stay`, holding all.
Eigen::Vector3d nearest_in_front(const MeshWalk& walk, const Eigen::Vector3d& goal, const Eigen::Vector3d& stay,
                                 unsigned& held_out) {
  Eigen::Vector3d best = stay;
  held_out = (1u << walk.count) - 1u;
  double best_squared = std::numeric_limits<double>::infinity();
  for (unsigned held = 0; held < (1u << walk.count); ++held) {
    if (std::popcount(held) > 3) continue;  // three planes fix a point: a fourth held is never needed
    Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    int size = 0;
    for (int i = 0; i < walk.count; ++i) {
      if (((held >> i) & 1u) == 0) continue;
      const auto s = static_cast<std::size_t>(i);
      normals.col(size) = walk.normal[s];
      rhs[size] = walk.normal[s].dot(walk.point_m[s] - goal);  // n·(goal + N·λ − p) = 0 on each held plane
      ++size;
    }
    Eigen::Vector3d y = goal;
    if (size > 0) {
      const Eigen::Matrix3d gram = normals.transpose() * normals;
      const double determinant = size == 1 ? 1.0 : size == 2 ? gram.topLeftCorner<2, 2>().determinant()
                                                              : gram.determinant();
      if (!(determinant > kParallelGram)) continue;
      const Eigen::Vector3d lambda = gram_solve(normals, size, rhs);
      if ((lambda.head(size).array() < 0.0).any()) continue;  // a held plane would pull the point in
      y = goal + normals.leftCols(size) * lambda.head(size);
    }
    bool in_front = true;
    for (int i = 0; i < walk.count && in_front; ++i) {
      const auto s = static_cast<std::size_t>(i);
      in_front = walk.normal[s].dot(y - walk.point_m[s]) >= -kOnSurface_m;
    }
    const double squared = (y - goal).squaredNorm();
    if (in_front && squared < best_squared) {
      best = y;
      best_squared = squared;
      held_out = held;
    }
  }
  return best;
}

void add(MeshWalk& walk, const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal, std::uint32_t triangle,
         int mesh) {
  const auto s = static_cast<std::size_t>(walk.count++);
  walk.point_m[s] = point_m;
  walk.normal[s] = normal;
  walk.triangle[s] = triangle;
  walk.mesh[s] = mesh;
}

// Keeps the planes whose bits are set in `held`, in order.
void keep(MeshWalk& walk, unsigned held) {
  int kept = 0;
  for (int i = 0; i < walk.count; ++i) {
    if (((held >> i) & 1u) == 0) continue;
    const auto from = static_cast<std::size_t>(i), to = static_cast<std::size_t>(kept++);
    walk.point_m[to] = walk.point_m[from];
    walk.normal[to] = walk.normal[from];
    walk.triangle[to] = walk.triangle[from];
    walk.mesh[to] = walk.mesh[from];
  }
  walk.count = kept;
}

// The triangles of a plane's mesh if this process has them, else null (not a mesh, or not loaded here).
const MeshGeometry* geometry_of(const ContactPlane& plane) {
  return plane.shape.kind == ShapeKind::mesh ? find_mesh_geometry(plane.shape.mesh_hash) : nullptr;
}

// Which of `meshes` is scene object `object_id`, or −1.
int index_of_object(std::span<const WalkedMesh> meshes, std::int32_t object_id) {
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    if (meshes[m].object_id == object_id) return static_cast<int>(m);
  }
  return -1;
}

Eigen::Vector3d to_body(const WalkedMesh& placed, const Eigen::Vector3d& x_m) {
  return placed.axes.transpose() * (x_m - placed.com_m);
}

// Whether `x_m` (world frame) lies on triangle `triangle` of `placed`, to the walk's tolerance; `on` gets the
// triangle's plane there, in the body frame.
bool on_triangle(const WalkedMesh& placed, std::uint32_t triangle, const Eigen::Vector3d& x_m, MeshEntry& on) {
  return placed.mesh->on_triangle(triangle, to_body(placed, x_m), kOnSurface_m, on);
}

// The first triangle of any mesh that the way from `from_m` to `to_m` goes in through (the held ones of each mesh
// skipped), in the world frame; false if none.
bool first_entry(std::span<const WalkedMesh> meshes, const MeshWalk& walk, const Eigen::Vector3d& from_m,
                 const Eigen::Vector3d& to_m, MeshEntry& out, int& out_mesh) {
  double best_t = std::numeric_limits<double>::infinity();
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    std::array<std::uint32_t, MeshWalk::kCapacity> skip{};
    int skip_count = 0;
    for (int i = 0; i < walk.count; ++i) {
      if (walk.mesh[static_cast<std::size_t>(i)] == static_cast<int>(m)) {
        skip[static_cast<std::size_t>(skip_count++)] = walk.triangle[static_cast<std::size_t>(i)];
      }
    }
    const WalkedMesh& placed = meshes[m];
    MeshEntry entry;
    if (!placed.mesh->first_entry(to_body(placed, from_m), to_body(placed, to_m), kOnSurface_m, skip.data(),
                                  skip_count, entry) ||
        entry.t >= best_t) {
      continue;
    }
    best_t = entry.t;
    out.point_m = placed.com_m + placed.axes * entry.point_m;
    out.normal = placed.axes * entry.normal;
    out.t = entry.t;
    out.triangle = entry.triangle;
    out_mesh = static_cast<int>(m);
  }
  return best_t <= 1.0;
}

}  // namespace

MeshWalk walk_meshes(std::span<const WalkedMesh> meshes, const Eigen::Vector3d& proxy_m,
                     const Eigen::Vector3d& finger_m, const MeshHold* held) {
  MeshWalk walk;
  Eigen::Vector3d x = proxy_m;
  // A proxy inside at the start: a body moved onto it since the last tick. It starts from the surface, held by the
  // plane there, so the body pushes the finger. Only a body that moves comes over the proxy (a static one's surface
  // was where the last walk left the proxy, in front of it), and only a closed mesh has an inside (behind its
  // pseudo-normals); a moving mesh is closed (mesh_check.h).
  for (std::size_t m = 0; m < meshes.size() && walk.count < kMaxActiveConstraints; ++m) {
    const WalkedMesh& placed = meshes[m];
    if (!placed.moves || !placed.mesh->closed()) continue;
    const SurfacePoint at_proxy = placed.mesh->nearest(to_body(placed, proxy_m));
    if (at_proxy.signed_distance_m < -kOnSurface_m) {
      add(walk, placed.com_m + placed.axes * at_proxy.point_m, placed.axes * at_proxy.normal, MeshWalk::kNoTriangle,
          static_cast<int>(m));
    }
  }
  if (walk.count > 0) {
    unsigned kept = 0;
    x = nearest_in_front(walk, proxy_m, proxy_m, kept);
  } else if (held != nullptr) {
    // The last walk's triangles that the proxy lies on, with the finger behind: the first step's way would go in
    // through each at t = 0 (first_entry's rule, to the same tolerance), so they are met already.
    for (int i = 0; i < held->count; ++i) {
      const auto s = static_cast<std::size_t>(i);
      const int m = index_of_object(meshes, held->object_id[s]);
      if (m < 0) continue;
      const WalkedMesh& placed = meshes[static_cast<std::size_t>(m)];
      MeshEntry on;
      if (on_triangle(placed, held->triangle[s], x, on) &&
          on.normal.dot(to_body(placed, finger_m) - on.point_m) < -kOnSurface_m) {
        add(walk, placed.com_m + placed.axes * on.point_m, placed.axes * on.normal, on.triangle, m);
      }
    }
  }
  for (int step = 0; step < kMaxSteps; ++step) {
    // Head for the point nearest the finger in front of the planes met; those it does not hold are left behind (the
    // way from here to it stays in front of them: both ends are) and make room for the next.
    unsigned held = 0;
    const Eigen::Vector3d goal = nearest_in_front(walk, finger_m, x, held);
    keep(walk, held);
    MeshEntry entry;
    int mesh = 0;
    if (!first_entry(meshes, walk, x, goal, entry, mesh)) {
      x = goal;
      break;
    }
    x = entry.point_m;
    add(walk, entry.point_m, entry.normal, entry.triangle, mesh);
  }
  if (walk.count > kMaxActiveConstraints) {
    unsigned held = 0;  // the steps ran out with a fourth plane met: the three the finger's point holds
    nearest_in_front(walk, finger_m, x, held);
    keep(walk, held);
  }
  walk.proxy_m = x;
  return walk;
}

Eigen::Vector3d stop_at_meshes(const PlaneSet& planes, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                               const MeshHold* held) {
  std::array<WalkedMesh, kMaxPlanes> meshes;
  std::size_t count = 0;
  for (std::uint32_t k = 0; k < planes.count && count < meshes.size(); ++k) {
    const ContactPlane& plane = planes.planes[k];
    const MeshGeometry* mesh = geometry_of(plane);
    if (mesh == nullptr) continue;
    // A convex body lies behind each of its planes the god-object holds (a triangle's, or the tangent plane of one the
    // walk held nothing of), and the proxy is in front of them: only a mesh with a concave bend can be gone into.
    if (mesh->convex()) continue;
    // A mesh the walk held several triangles of has a plane for each: listed once.
    if (index_of_object(std::span<const WalkedMesh>(meshes.data(), count), plane.object_id) < 0) {
      meshes[count++] = {mesh, plane.com_m, plane.axes, plane.dynamic(), plane.object_id};
    }
  }
  const std::span<const WalkedMesh> listed(meshes.data(), count);
  // Both ends on one held triangle: the way between them is on it too (a triangle is convex).
  for (int i = 0; held != nullptr && i < held->count; ++i) {
    const auto s = static_cast<std::size_t>(i);
    const int m = index_of_object(listed, held->object_id[s]);
    MeshEntry on;
    if (m >= 0 && on_triangle(listed[static_cast<std::size_t>(m)], held->triangle[s], from_m, on) &&
        on_triangle(listed[static_cast<std::size_t>(m)], held->triangle[s], to_m, on)) {
      return to_m;
    }
  }
  MeshEntry entry;
  int mesh = 0;
  const MeshWalk none;
  return count > 0 && first_entry(listed, none, from_m, to_m, entry, mesh) ? entry.point_m : to_m;
}

MeshHold held_by(const MeshWalk& walk, std::span<const WalkedMesh> meshes) {
  MeshHold hold;
  for (int i = 0; i < walk.count && hold.count < 3; ++i) {
    const auto s = static_cast<std::size_t>(i);
    if (walk.triangle[s] == MeshWalk::kNoTriangle) continue;  // a plane, not a triangle: nothing to start from
    const auto h = static_cast<std::size_t>(hold.count++);
    hold.object_id[h] = meshes[static_cast<std::size_t>(walk.mesh[s])].object_id;
    hold.triangle[h] = walk.triangle[s];
  }
  return hold;
}

int walk_mesh_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m,
                     std::span<bool> walked, MeshHold* hold) {
  std::array<WalkedMesh, kMaxPlanes> meshes;
  std::array<std::uint32_t, kMaxPlanes> plane_of;  // meshes[m] is planes.planes[plane_of[m]]
  std::size_t count = 0;
  for (std::uint32_t k = 0; k < planes.count && count < meshes.size(); ++k) {
    const ContactPlane& plane = planes.planes[k];
    const MeshGeometry* mesh = geometry_of(plane);
    if (mesh == nullptr) continue;
    meshes[count] = {mesh, plane.com_m, plane.axes, plane.dynamic(), plane.object_id};
    plane_of[count++] = k;
    walked[k] = true;
  }
  if (count == 0) {
    if (hold != nullptr) *hold = MeshHold{};
    return 0;
  }
  const MeshWalk walk = walk_meshes(std::span<const WalkedMesh>(meshes.data(), count), proxy_m, finger_m, hold);
  if (hold != nullptr) {
    *hold = held_by(walk, std::span<const WalkedMesh>(meshes.data(), count));
    hold->end_m = walk.proxy_m;
    hold->walked = true;
  }
  for (std::size_t m = 0; m < count; ++m) {
    ContactPlane& plane = planes.planes[plane_of[m]];
    bool first = true;
    for (int i = 0; i < walk.count; ++i) {
      const auto s = static_cast<std::size_t>(i);
      if (walk.mesh[s] != static_cast<int>(m)) continue;
      if (!first && planes.count >= kMaxServoPlanes) break;  // never: three held at most, one in the mesh's place
      ContactPlane& into = first ? plane : planes.planes[planes.count++];
      if (!first) into = plane;
      into.point_m = walk.point_m[s];
      into.normal = walk.normal[s];
      into.met = true;
      first = false;
    }
    if (first) retake_plane(plane, walk.proxy_m);  // none held: about where the walk ended
  }
  return walk.count;
}

}  // namespace impetus
