// SPDX-License-Identifier: Apache-2.0
#pragma once
// The god-object on meshes' own triangles (Zilles & Salisbury 1995; docs/meshes.md "The exact god-object"). A mesh
// is not one plane: in a crease or a bowl the surface the proxy must stay outside of is several triangles at once, and
// the tangent plane at one point, slid along, goes into the others. So each tick the proxy walks from where it was
// toward the finger over the triangles of every mesh in reach:
//   1. head for the point nearest the finger in front of the triangles met so far (none at first);
//   2. stop where the way first goes in through a triangle's outer side, of whichever mesh, and add that triangle;
//   3. repeat from there; a triangle the new heading no longer presses on is left behind, so at most three are held
//      at once (a face, a crease's two, a corner's three, of one mesh or of several touching).
// The triangles held at the end are the meshes' constraints this tick, each its own plane; the god-object
// (proxy_projection.h) then solves them with the primitives' planes, and its projection of the finger onto the walk's
// triangles is where the walk ended. A convex edge is rounded over ticks, as Zilles & Salisbury's proxy does: past the
// edge the way no longer goes into the first face, and the next tick's way goes into the next.
//
// Only a way that goes in from the outside counts, so a thin wall holds from its outer side however far the finger
// has gone through it, and a finger leaving a mesh is never held by the far side. A proxy that a moving body has come
// over (inside a closed, dynamic mesh at the start of the tick) starts from the surface nearest it, held by the plane
// there: the body pushes the finger, as it arrives.
//
// The walk may start from the triangles the last tick's walk held (MeshHold). A triangle the proxy still lies on, with
// the finger behind it, is the one the first step's way would go in through at once (t = 0), so it is taken as met
// without asking the tree: one segment query a tick fewer while the proxy presses on a face. Allocation-free.

#include "common/shape/mesh_geometry.h"
#include "haptic_controller/contact_plane.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>

namespace impetus {

// A mesh as placed this tick: its triangles and the pose of its body frame (centre and axes, world frame). No
// default values: the servo keeps an array of them uninitialised and fills what it uses.
struct WalkedMesh {
  const MeshGeometry* mesh;
  Eigen::Vector3d com_m;
  Eigen::Matrix3d axes;  // columns: body x, y, z in the world frame
  bool moves;            // a dynamic body: it may have come over the proxy since the last tick
  std::int32_t object_id;  // the scene object it is (two objects may share one mesh's triangles)
};

// The triangles a walk held at its end, by object and triangle: where the next tick's walk may start from. And where
// it ended, a point outside every mesh walked (`walked` false: no mesh was in reach this tick).
struct MeshHold {
  std::array<std::int32_t, 3> object_id{};
  std::array<std::uint32_t, 3> triangle{};
  int count = 0;
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();
  bool walked = false;
};

// The triangles the walk holds at its end (their planes, world frame: a point on each and its outward unit normal,
// and which mesh), and where it ended.
struct MeshWalk {
  // Three planes fix a point (kMaxActiveConstraints); room for a fourth met on the way, before one is left behind.
  static constexpr int kCapacity = 4;
  static constexpr std::uint32_t kNoTriangle = 0xffffffffu;  // the start's plane under a body that moved onto it
  std::array<Eigen::Vector3d, kCapacity> point_m{};
  std::array<Eigen::Vector3d, kCapacity> normal{};
  std::array<std::uint32_t, kCapacity> triangle{};
  std::array<int, kCapacity> mesh{};  // index into the meshes walked
  int count = 0;                      // at most 3 when the walk returns
  Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();
};

// The walk from `proxy_m` toward `finger_m` (world frame) over `meshes`, started from the triangles of `held` that
// the proxy still lies on (none if null).
MeshWalk walk_meshes(std::span<const WalkedMesh> meshes, const Eigen::Vector3d& proxy_m,
                     const Eigen::Vector3d& finger_m, const MeshHold* held = nullptr);

// Where the way from `from_m` (outside every mesh) toward `to_m` first goes into a mesh of `planes` whose triangles
// this process has, or `to_m` if into none. Friction moves the proxy off the walk's end along the planes of the
// triangles held, and a triangle's plane runs on past its edge: beyond a concave crease, behind the neighbour. The
// god-object walks that move too (god_object.h). With `held` (the walk's, from_m its end), a move from one point of a
// held triangle to another stays on it and asks no tree.
Eigen::Vector3d stop_at_meshes(const PlaneSet& planes, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                               const MeshHold* held = nullptr);

// What `walk` holds at its end, for the next tick's walk over the same `meshes`.
MeshHold held_by(const MeshWalk& walk, std::span<const WalkedMesh> meshes);

// The servo's use (shape_planes.h): walks every plane of `planes` whose mesh this process has (find_mesh_geometry of
// its hash). A mesh whose triangles the walk holds gets them as its planes, marked met (ContactPlane::met): the first
// in its own place, the others added at the end of the set with the same object. A mesh it holds none of gets its
// plane about where the walk ended, as a retake does (the tangent plane at the mesh's point nearest it: the walk's
// end is in front of it). `walked[k]` is set for every mesh plane k. Returns the triangles held (0: the proxy reaches
// the finger past every mesh). With `hold`, the walk starts from what it holds and leaves there what this walk held.
int walk_mesh_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m,
                     std::span<bool> walked, MeshHold* hold = nullptr);

}  // namespace impetus
