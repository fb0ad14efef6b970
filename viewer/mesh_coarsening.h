// SPDX-License-Identifier: Apache-2.0
#pragma once
// A mesh too fine to send to a page (a terrain of 10^6 triangles) made coarse enough to draw: vertex clustering
// (Rossignac and Borrel 1993). Space is cut into cubic cells; the vertices in a cell merge into one at their mean, a
// triangle whose corners fall in three different cells is kept on those, and the rest (folded to a line or a point,
// or the same three cells again) are dropped. The cell grows until the triangles left fit the limit, so the shape is
// kept to about a cell. For the viewer only: not exact, not for contacts. Allocates; not for any real-time path.

#include "common/mesh/triangle_mesh.h"

#include <cstddef>

namespace impetus::view {

struct CoarseMesh {
  TriangleMesh mesh;
  double cell_m = 0.0;  // the cells' edge; 0 when the mesh was kept as it was
};

// `mesh` itself if it has at most `max_triangles`, else its clustering on the smallest cell (growing by a quarter from
// the bounding box's diagonal over √max_triangles) whose triangles number at most `max_triangles`.
CoarseMesh coarsened(const TriangleMesh& mesh, std::size_t max_triangles);

}  // namespace impetus::view
