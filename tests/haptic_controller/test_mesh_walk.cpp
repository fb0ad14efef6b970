// SPDX-License-Identifier: Apache-2.0
// The god-object's walk over a mesh's triangles (haptic_controller/mesh_walk.h), against answers known exactly: the
// inside corner of three faces (the free space is an octant, so the proxy is the finger clamped to it), a spherical
// cavity (the proxy stays in front of every triangle and on the surface), a 1 mm slab crossed at 3 m/s, a convex edge
// left, a mesh arriving at a still finger, and two bodies: the crease where they meet, and the nearer of two on the
// way.

#include "common/mesh/mesh_bvh.h"
#include "haptic_controller/god_object.h"
#include "haptic_controller/mesh_walk.h"
#include "haptic_controller/proxy_projection.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/mesh_shapes.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace impetus;
using Eigen::Vector3d;

namespace {

// The walk's view of a tree built here (the servo's comes from the mesh registry).
class TreeGeometry final : public MeshGeometry {
 public:
  TreeGeometry(TriangleMesh mesh, bool closed) : tree_(std::move(mesh)), closed_(closed) {}
  bool closed() const override { return closed_; }
  bool convex() const override { return closed_ && tree_.locally_convex(); }
  SurfacePoint nearest(const Vector3d& query_m) const override {
    MeshPoint point;
    tree_.nearest(query_m, point);
    return {point.point_m, point.normal, point.signed_distance_m};
  }
  double support(const Vector3d&) const override { return 0.0; }
  bool segment_enters(const Vector3d&, const Vector3d&, double) const override { return false; }
  bool first_entry(const Vector3d& a, const Vector3d& b, double tolerance_m, const std::uint32_t* skip,
                   int skip_count, MeshEntry& out) const override {
    ++segment_queries;
    return tree_.first_entry(a, b, tolerance_m, skip, skip_count, out);
  }
  bool on_triangle(std::uint32_t triangle, const Vector3d& x, double tolerance_m, MeshEntry& out) const override {
    return tree_.on_triangle(triangle, x, tolerance_m, out);
  }
  Vector3d bounds_half(const Eigen::Matrix3d&) const override { return Vector3d::Zero(); }
  double volume_m3() const override { return 0.0; }
  Eigen::Matrix3d inertia_per_kg() const override { return Eigen::Matrix3d::Zero(); }
  const TriangleMesh& mesh() const { return tree_.mesh(); }
  mutable long segment_queries = 0;  // first_entry calls

  // The least height of `x` over every triangle's plane whose triangle its foot point lies on (brute force): < 0 is
  // behind the surface there.
  double worst_height_m(const Vector3d& x) const {
    double worst = std::numeric_limits<double>::infinity();
    for (const auto& tri : mesh().triangles) {
      const Vector3d& a = mesh().vertices_m[tri[0]];
      const Vector3d& b = mesh().vertices_m[tri[1]];
      const Vector3d& c = mesh().vertices_m[tri[2]];
      const Vector3d n = (b - a).cross(c - a).normalized();
      const Vector3d foot = x - n.dot(x - a) * n;
      const bool over = (b - a).cross(foot - a).dot(n) >= 0 && (c - b).cross(foot - b).dot(n) >= 0 &&
                        (a - c).cross(foot - c).dot(n) >= 0;
      if (over) worst = std::min(worst, n.dot(x - a));
    }
    return worst;
  }

 private:
  MeshBvh tree_;
  bool closed_;
};

// Three square faces of side `side_m` on the planes x = 0, y = 0 and z = 0, meeting at the origin and facing into
// the positive octant, each an n×n grid of squares split in two (a crease the walk crosses many triangles along).
TriangleMesh inside_corner(double side_m, int n) {
  TriangleMesh mesh;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // u × v = the axis: the face looks along +axis
    const auto first = static_cast<std::uint32_t>(mesh.vertices_m.size());
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        Vector3d p = Vector3d::Zero();
        p[u] = side_m * i / n;
        p[v] = side_m * j / n;
        mesh.vertices_m.push_back(p);
      }
    }
    auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(i * (n + 1) + j); };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  }
  return mesh;
}

// The walk over one mesh placed at the world's origin, unturned. With `hold`, started from what it holds, as the servo
// does, and leaving there what this walk held; every tick-by-tick case runs both ways and must give the same answer.
MeshWalk walk_mesh(const MeshGeometry& mesh, const Vector3d& proxy_m, const Vector3d& finger_m,
                   MeshHold* hold = nullptr) {
  const WalkedMesh placed{&mesh, Vector3d::Zero(), Eigen::Matrix3d::Identity(), true, 0};
  const std::span<const WalkedMesh> meshes(&placed, 1);
  const MeshWalk walk = walk_meshes(meshes, proxy_m, finger_m, hold);
  if (hold != nullptr) *hold = held_by(walk, meshes);
  return walk;
}

// The walk's planes as the god-object gets them, and its projection of the finger onto them.
Vector3d projected_on_walk(const MeshWalk& walk, const Vector3d& finger_m) {
  PlaneSet planes;
  for (int i = 0; i < walk.count; ++i) {
    ContactPlane& plane = planes.planes[planes.count++];
    plane.point_m = walk.point_m[static_cast<std::size_t>(i)];
    plane.normal = walk.normal[static_cast<std::size_t>(i)];
  }
  return project_outside_planes(planes, finger_m).proxy_m;
}

}  // namespace

TEST_CASE("mesh walk: dragged into the inside corner of three faces, the proxy is the finger clamped to the octant") {
  MeshHold hold;
  MeshHold* const started_from_last = GENERATE(false, true) ? &hold : nullptr;
  const TreeGeometry corner(inside_corner(0.05, 10), false);
  // The finger comes in from the open side and is dragged along each crease and into the corner, 0.5–3 mm a tick,
  // up to 8 mm behind the faces; the proxy follows from tick to tick.
  Vector3d proxy = Vector3d(0.02, 0.02, 0.02);
  const Vector3d waypoints[] = {{0.02, 0.02, 0.02},    {0.02, 0.02, -0.004},  {0.02, -0.006, -0.004},
                                {-0.008, -0.006, -0.004}, {0.03, -0.002, -0.007}, {0.001, 0.03, -0.003},
                                {-0.005, 0.002, 0.02},   {-0.003, -0.003, -0.003}, {0.02, 0.02, 0.02}};
  int ticks = 0, corners = 0;
  double worst_m = 0.0, worst_solver_m = 0.0;
  for (std::size_t w = 0; w + 1 < std::size(waypoints); ++w) {
    const Vector3d from = waypoints[w], to = waypoints[w + 1];
    const int steps = static_cast<int>(std::ceil((to - from).norm() / 0.0017));
    for (int s = 1; s <= steps; ++s) {
      const Vector3d finger = from + (to - from) * (static_cast<double>(s) / steps);
      const MeshWalk walk = walk_mesh(corner, proxy, finger, started_from_last);
      proxy = walk.proxy_m;
      worst_m = std::max(worst_m, (proxy - finger.cwiseMax(0.0)).norm());
      // The god-object, given the walk's planes, puts the proxy where the walk did.
      worst_solver_m = std::max(worst_solver_m, (projected_on_walk(walk, finger) - proxy).norm());
      REQUIRE(walk.count <= kMaxActiveConstraints);
      if (walk.count == 3) ++corners;
      ++ticks;
    }
  }
  INFO(ticks << " ticks, " << corners << " at the corner");
  CHECK(worst_m < 1e-12);
  CHECK(worst_solver_m < 1e-12);
  CHECK(corners > 5);  // the finger was behind all three faces, and three triangles held the proxy
}

TEST_CASE("mesh walk: pressed 3 mm out of a spherical cavity and slid round it, the proxy stays on its surface") {
  MeshHold hold;
  MeshHold* const started_from_last = GENERATE(false, true) ? &hold : nullptr;
  // The inside of a ball of 5 cm radius: an icosphere of 1280 triangles wound inward, a closed cavity whose free space
  // is the polyhedron they bound. The finger circles 3 mm beyond the sphere at 0.1 m/s, crossing many triangles.
  TriangleMesh cavity = test::icosphere(0.05, 3);
  for (auto& tri : cavity.triangles) std::swap(tri[1], tri[2]);
  const TreeGeometry geometry(std::move(cavity), true);
  Vector3d proxy = Vector3d::Zero();
  double deepest_m = 0.0, highest_m = 0.0, worst_solver_m = 0.0;
  for (int tick = 0; tick < 3000; ++tick) {
    const double angle = 2.0 * tick * 1e-3;  // 0.1 m/s at 5 cm
    const Vector3d direction = Vector3d(std::cos(angle), std::sin(angle), 0.3 * std::sin(3 * angle)).normalized();
    const Vector3d finger = 0.053 * direction;
    const MeshWalk walk = walk_mesh(geometry, proxy, finger, started_from_last);
    proxy = walk.proxy_m;
    deepest_m = std::min(deepest_m, geometry.worst_height_m(proxy));
    // Pressed from the first tick on: on the surface, its distance to the nearest triangle nil.
    if (tick > 100) highest_m = std::max(highest_m, geometry.nearest(proxy).signed_distance_m);
    worst_solver_m = std::max(worst_solver_m, (projected_on_walk(walk, finger) - proxy).norm());
  }
  INFO("deepest " << deepest_m << " m, highest " << highest_m << " m");
  CHECK(deepest_m > -1e-12);   // never behind a triangle it is over
  CHECK(highest_m < 1e-12);    // and on one: pressed, the proxy is on the surface
  CHECK(worst_solver_m < 1e-12);
}

TEST_CASE("mesh walk: started from the triangles it held, the walk asks the tree less and ends where it did") {
  // The cavity of the case above, the finger circling 3 mm beyond it: walked from scratch each tick, and started from
  // the last tick's triangles.
  TriangleMesh cavity = test::icosphere(0.05, 3);
  for (auto& tri : cavity.triangles) std::swap(tri[1], tri[2]);
  const TreeGeometry scratch(cavity, true), started(std::move(cavity), true);
  Vector3d proxy_scratch = Vector3d::Zero(), proxy_started = Vector3d::Zero();
  MeshHold hold;
  double apart_m = 0.0;
  for (int tick = 0; tick < 3000; ++tick) {
    const double angle = 2.0 * tick * 1e-3;
    const Vector3d finger = 0.053 * Vector3d(std::cos(angle), std::sin(angle), 0.3 * std::sin(3 * angle)).normalized();
    proxy_scratch = walk_mesh(scratch, proxy_scratch, finger).proxy_m;
    proxy_started = walk_mesh(started, proxy_started, finger, &hold).proxy_m;
    apart_m = std::max(apart_m, (proxy_scratch - proxy_started).norm());
  }
  INFO("segment queries: " << scratch.segment_queries << " from scratch, " << started.segment_queries << " started");
  CHECK(apart_m < 1e-12);
  // Pressed on a face nearly every tick, the started walk skips the first query nearly every tick.
  CHECK(started.segment_queries < scratch.segment_queries - 2500);
}

TEST_CASE("mesh walk: a 1 mm slab crossed at 3 m/s holds the proxy on its top face every tick") {
  MeshHold hold;
  MeshHold* const started_from_last = GENERATE(false, true) ? &hold : nullptr;
  const TreeGeometry slab(test::box_mesh(Vector3d(0.1, 0.1, 0.001)), true);
  Vector3d proxy(0.01, 0.0, 0.005);
  for (int tick = 1; tick <= 6; ++tick) {
    const Vector3d finger(0.01 + 0.001 * tick, 0.0, 0.005 - 0.003 * tick);  // 3 mm a tick downward
    const MeshWalk walk = walk_mesh(slab, proxy, finger, started_from_last);
    proxy = walk.proxy_m;
    if (finger.z() < 0.0005) {
      CHECK(walk.count == 1);
      CHECK(std::abs(proxy.z() - 0.0005) < 1e-15);  // the top face, never the bottom one the finger is past
      CHECK(std::abs(proxy.x() - finger.x()) < 1e-15);
    }
  }
}

TEST_CASE("mesh walk: a finger that slides off a box's edge is let go within a tick of leaving the box") {
  MeshHold hold;
  MeshHold* const started_from_last = GENERATE(false, true) ? &hold : nullptr;
  const TreeGeometry box(test::box_mesh(Vector3d(0.04, 0.04, 0.04)), true);  // top face z = 0.02, side x = 0.02
  Vector3d proxy(0.0, 0.0, 0.03);
  int held_outside = 0;
  for (int tick = 0; tick < 40; ++tick) {
    const Vector3d finger(0.015 + 0.0005 * tick, 0.0, 0.017);  // 3 mm into the top face, sliding out past x = 0.02
    const MeshWalk walk = walk_mesh(box, proxy, finger, started_from_last);
    proxy = walk.proxy_m;
    if (finger.x() > 0.02) {
      if (walk.count > 0) ++held_outside;
      else CHECK(proxy == finger);
    } else {
      CHECK(walk.count == 1);
      CHECK(std::abs(proxy.z() - 0.02) < 1e-15);
    }
  }
  CHECK(held_outside <= 1);  // the tick it crosses the edge's line, the top face's plane still holds it once
}

TEST_CASE("mesh walk: a box arriving at a still finger pushes its proxy out on the face it arrives with") {
  const TreeGeometry box(test::box_mesh(Vector3d(0.04, 0.04, 0.04)), true);
  // Body frame: the box comes along −x at 1 mm a tick toward a finger that stays where it is in the world; in the
  // box's frame the finger (and last tick's proxy) come 1 mm further in through its +x face each tick.
  Vector3d proxy(0.0225, 0.003, 0.001);
  for (int tick = 1; tick <= 5; ++tick) {
    const Vector3d finger(0.0225 - 0.001 * tick, 0.003, 0.001);
    const Vector3d last_proxy_now = proxy - Vector3d(0.001, 0.0, 0.0);  // where the world left it, as the box moved
    const MeshWalk walk = walk_mesh(box, last_proxy_now, finger);
    proxy = walk.proxy_m;
    if (finger.x() < 0.02) {
      CHECK(walk.count >= 1);
      CHECK(std::abs(proxy.x() - 0.02) < 1e-15);  // on the +x face: the spring pushes the finger out along +x
      CHECK(proxy.y() == Approx(finger.y()).margin(1e-15));
    }
  }
}

TEST_CASE("mesh walk: two bodies, turned and apart: held in the crease where they meet, and by the nearer on the way") {
  // A floor slab and a wall standing on it, each its own mesh and pose: the wall's frame turned a quarter turn about
  // y. Their inside crease runs along y at x = 0, z = 0: the free space there is x ≥ 0 and z ≥ 0.
  const TreeGeometry slab(test::box_mesh(Vector3d(0.1, 0.1, 0.02)), true);
  const TreeGeometry wall(test::box_mesh(Vector3d(0.06, 0.1, 0.02)), true);  // 6 cm tall once turned
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d unturned = Eigen::Matrix3d::Identity();
  const std::array<WalkedMesh, 2> bodies{WalkedMesh{&slab, Vector3d(0.0, 0.0, -0.01), unturned, false, 0},
                                         WalkedMesh{&wall, Vector3d(-0.01, 0.0, 0.03), quarter, false, 1}};
  Vector3d proxy(0.02, 0.0, 0.02);
  double worst_m = 0.0;
  int both = 0;
  for (int tick = 1; tick <= 40; ++tick) {
    const Vector3d finger(0.02 - 0.0008 * tick, 0.0005 * tick, 0.02 - 0.0007 * tick);  // into the crease and past it
    const MeshWalk walk = walk_meshes(bodies, proxy, finger);
    proxy = walk.proxy_m;
    worst_m = std::max(worst_m, (proxy - Vector3d(std::max(finger.x(), 0.0), finger.y(), std::max(finger.z(), 0.0)))
                                    .norm());
    if (walk.count == 2 && walk.mesh[0] != walk.mesh[1]) ++both;
  }
  CHECK(worst_m < 1e-12);
  CHECK(both > 5);  // a triangle of each body held the proxy at once

  // A finger gone through the slab and on into a second one below: held by the top of the first, never the second.
  const std::array<WalkedMesh, 2> stacked{WalkedMesh{&slab, Vector3d(0.0, 0.0, -0.01), unturned, false, 0},
                                          WalkedMesh{&slab, Vector3d(0.0, 0.0, -0.05), unturned, false, 1}};
  const MeshWalk deep = walk_meshes(stacked, Vector3d(0.0, 0.0, 0.001), Vector3d(0.003, 0.0, -0.05));
  REQUIRE(deep.count == 1);
  CHECK(deep.mesh[0] == 0);
  CHECK(deep.proxy_m.isApprox(Vector3d(0.003, 0.0, 0.0), 1e-12));
}

TEST_CASE("mesh walk: a proxy stuck by friction on one side of a valley is not left behind the other side") {
  // A valley along y: a face rising to each side at 1:2 (z = |x|/2). The proxy sticks (μ = 2) on the left face 1 mm
  // from the crease; then the finger is far down to the right, pressing the right face only. The stick point, kept on
  // the active plane, is the old proxy projected onto the right face's plane: below the left face.
  TriangleMesh valley;
  valley.vertices_m = {{-0.05, -0.05, 0.025}, {-0.05, 0.05, 0.025}, {0.0, -0.05, 0.0},
                       {0.0, 0.05, 0.0},      {0.05, -0.05, 0.025}, {0.05, 0.05, 0.025}};
  valley.triangles = {{0, 2, 3}, {0, 3, 1}, {2, 4, 5}, {2, 5, 3}};  // wound up, out of the ground
  const TreeGeometry geometry(valley, false);
  constexpr std::uint64_t kHash = 0x5a11e7000000c0deull;  // this test's own
  register_mesh_geometry(kHash, &geometry);
  const auto below_faces_m = [](const Vector3d& x) {  // how far behind the nearer face, positive if behind
    const Vector3d left = Vector3d(0.5, 0.0, 1.0).normalized(), right = Vector3d(-0.5, 0.0, 1.0).normalized();
    return std::max(-(x.x() <= 0.0 ? left : right).dot(x), 0.0);
  };
  PlaneSet sent;
  ContactPlane& plane = sent.planes[sent.count++];
  plane.shape.kind = ShapeKind::mesh;
  plane.shape.mesh_hash = kHash;
  plane.shape.radius_m = 0.08;
  plane.object_id = 0;
  plane.com_m = Vector3d::Zero();
  plane.axes = Eigen::Matrix3d::Identity();
  plane.point_m = Vector3d::Zero();
  plane.normal = Vector3d::UnitZ();
  plane.static_friction = 2.0;
  plane.dynamic_friction = 1.5;
  GodObject god;
  MeshHold hold;
  Vector3d proxy(-0.001, 0.0, 0.002);
  const Vector3d fingers[] = {{-0.001, 0.0, -0.0015}, {-0.001, 0.0, -0.0015}, {0.003, 0.0, -0.004}};
  double deepest_m = 0.0;
  bool stuck = false;
  for (const Vector3d& finger : fingers) {
    PlaneSet planes = sent;
    std::array<bool, kMaxServoPlanes> walked{};
    walk_mesh_planes(planes, proxy, finger, walked, &hold);
    const GodObjectResult& solved = god.solve(planes, finger, 1e-3, &hold);
    proxy = solved.contact.proxy_m;
    stuck = solved.sticking;
    deepest_m = std::max(deepest_m, below_faces_m(proxy));
  }
  INFO("proxy " << proxy.transpose() << ", deepest " << deepest_m << " m behind a face");
  CHECK(stuck);  // the last tick stuck: the case is the one meant
  CHECK(deepest_m < 1e-12);
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("mesh walk: a walk allocates nothing") {
  const TreeGeometry corner(inside_corner(0.05, 10), false);
  Vector3d proxy(0.02, 0.02, 0.02);
  int held = 0;
  MeshHold hold;
  impetus::test::start_counting_allocations();
  for (int tick = 0; tick < 2000; ++tick) {
    const Vector3d finger(0.02 * std::cos(tick * 0.01), 0.02 * std::sin(tick * 0.013), 0.01 * std::sin(tick * 0.007));
    const MeshWalk walk = walk_mesh(corner, proxy, finger, &hold);
    proxy = walk.proxy_m;
    held += walk.count;
  }
  CHECK(impetus::test::stop_counting_allocations() == 0);
  CHECK(held > 0);
}
#endif
