// SPDX-License-Identifier: Apache-2.0
#pragma once
// A body's shape as plain data: what a scene gives, what a plane on the world link carries, what a viewer draws.
// What each kind means, and every function of a shape, is in common/shape/shape.h.

#include "common/contract/vec3.h"

#include <cstdint>
#include <type_traits>

namespace impetus {

// The value crosses links and lands in logs: never renumber, add new kinds at the end (and to shape.cpp's table).
enum class ShapeKind : std::uint32_t {
  none = 0,  // no shape: the floor's plane, or a plane that carries none
  box = 1,
  sphere = 2,
  capsule = 3,
  cylinder = 4,
  mesh = 5,
};
inline constexpr std::uint32_t kShapeKindCount = 6;

// A body's shape in its body frame: centred on the body's origin, which is its centre of mass, an axis of symmetry
// along body z. A tagged descriptor: `kind` says which fields are read; the others are zero.
struct Shape {
  ShapeKind kind = ShapeKind::none;
  std::uint32_t reserved = 0;  // keeps the layout in whole 64-bit words (links checksum it)
  Vec3 box_size_m{};           // box: full extents along body x, y, z
  double radius_m = 0.0;       // sphere, capsule, cylinder
  double length_m = 0.0;       // capsule: between the cap centres; cylinder: end to end; along body z
  // mesh: the content hash of its triangles as placed in the body frame (common/mesh/triangle_mesh.h mesh_hash), by
  // which a process that loaded the same file finds its geometry (common/shape/mesh_geometry.h). A mesh's
  // box_size_m is its bounding box's size and radius_m the radius about its centre of mass that holds it.
  std::uint64_t mesh_hash = 0;
};
static_assert(std::is_trivially_copyable_v<Shape>);

}  // namespace impetus
