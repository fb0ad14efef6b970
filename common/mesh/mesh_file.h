// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a user's mesh file (docs/meshes.md): OBJ, binary or ASCII STL, and whatever else Assimp (Debian's
// libassimp) reads. Faces are triangulated and identical vertices joined, so an STL's triangle soup becomes a mesh
// whose edges can be checked (mesh_check.h).

#include "common/mesh/triangle_mesh.h"

#include <Eigen/Core>

#include <string>

namespace impetus {

// Reads every mesh in `path` into one, scaled by `scale` per axis (a file in millimetres: 0.001). Throws InputError
// naming the file: missing or unreadable, not a mesh Assimp knows, no triangles, more than MeshLimits::kMaxTriangles,
// a coordinate that is not finite or beyond MeshLimits::kMaxCoordinate_m (naming the vertex).
TriangleMesh load_mesh(const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

}  // namespace impetus
