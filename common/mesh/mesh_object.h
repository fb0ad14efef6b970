// SPDX-License-Identifier: Apache-2.0
#pragma once
// A scene object of shape "mesh" (docs/meshes.md): `"file": "PATH"` (OBJ or STL, relative to the scene file's
// folder), optional `"scale"` (a number, or three for x, y, z; a file in millimetres: 0.001). The mesh is read and
// checked (common/mesh/mesh_body.h: a dynamic body's mesh must be closed) and registered for the shape module; the
// object's position_m is where the mesh's centre of mass goes (an open static mesh's: its bounding box's centre).
// The world manager reads them as it loads a scene; the haptic controller reads the same scene's meshes
// (load_scene_meshes) so that its servo renders their triangles, found by the hash each plane carries.

#include "common/runtime/json_node.h"
#include "common/shape/shape_descriptor.h"

#include <string>

namespace impetus {

// The shape of the mesh object `object` (a scene object's node) names. `scene_dir` is the folder relative paths start
// from (empty: the working directory). Throws InputError naming the scene, the key and what is wrong with the file.
Shape load_mesh_shape(const JsonNode& object, const std::string& scene_dir, bool dynamic);

// The folder a scene file's mesh paths are relative to: the file's own, or empty (the working directory) when
// `scene_source` names no file (a scene given as text).
std::string scene_folder(const std::string& scene_source);

// Reads and registers every mesh the scene file at `path` names, as the world manager does when it loads the scene,
// and returns how many objects are meshes. Reads only the objects' "shape", "file", "scale" and "dynamic" keys (the
// world manager checks the rest). Throws InputError naming the file and the key.
std::size_t load_scene_meshes(const std::string& path);

}  // namespace impetus
