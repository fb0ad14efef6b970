// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a mesh is made of, before anything uses it (docs/meshes.md): degenerate triangles, edges that are open or
// shared by more than two triangles, neighbours wound against each other, and, for a closed mesh, which way it faces.

#include "common/mesh/triangle_mesh.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace impetus {

struct MeshReport {
  std::size_t triangles = 0;
  std::size_t degenerate_triangles = 0;  // area below kMinTriangleArea_m2
  std::size_t open_edges = 0;            // used by one triangle
  std::size_t nonmanifold_edges = 0;     // used by three or more
  std::size_t misoriented_edges = 0;     // two triangles that run the edge the same way: wound against each other
  double signed_volume_m3 = 0.0;         // Σ over triangles of a·(b × c)/6; negative: wound inside out
  std::int64_t first_degenerate = -1;    // index of the first triangle of each kind, −1 if none
  std::int64_t first_open = -1;
  std::int64_t first_nonmanifold = -1;
  std::int64_t first_misoriented = -1;

  // Closed, two triangles at every edge, consistently wound: a solid's surface.
  bool closed() const { return open_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0; }
};

// A triangle below 10⁻¹⁸ m² (a micrometre square) has no direction a normal could be taken from.
inline constexpr double kMinTriangleArea_m2 = 1e-18;

MeshReport check_mesh(const TriangleMesh& mesh);

// Turns every triangle around (b and c swapped): a closed mesh wound inside out (signed volume < 0) faces out again.
void flip_winding(TriangleMesh& mesh);

// For a body that moves (`dynamic`): the mesh must be closed, free of degenerate triangles and enclose a volume; one
// wound inside out is turned around. A static mesh may be open (a terrain, a shell) but not degenerate. Throws
// InputError naming `source` and the first triangle at fault; returns what was found (after any flip), and sets
// `flipped` when the winding was turned around.
MeshReport require_usable(TriangleMesh& mesh, bool dynamic, const std::string& source, bool& flipped);

}  // namespace impetus
