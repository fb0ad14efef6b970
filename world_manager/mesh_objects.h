// SPDX-License-Identifier: Apache-2.0
#pragma once
// A scene object of shape "mesh" (docs/meshes.md): `"file": "PATH"` (OBJ or STL, relative to the scene file's
// folder), optional `"scale"` (a number, or three for x, y, z; a file in millimetres: 0.001). The mesh is read and
// checked (common/mesh/mesh_body.h: a dynamic body's mesh must be closed) and registered for the shape module; the
// object's position_m is where the mesh's centre of mass goes (an open static mesh's: its bounding box's centre).

#include "common/runtime/json_node.h"
#include "common/shape/shape_descriptor.h"

#include <string>

namespace impetus {

// The shape of the mesh object `object` (a scene object's node) names. `scene_dir` is the folder relative paths start
// from (empty: the working directory). Throws SceneError naming the scene, the key and what is wrong with the file.
Shape load_mesh_shape(const JsonNode& object, const std::string& scene_dir, bool dynamic);

}  // namespace impetus
