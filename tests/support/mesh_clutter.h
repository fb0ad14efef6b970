// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ghost-force scorer's scenes (ghost_score.h) with every object made a user's mesh of about the same size, in the
// same pose: a box as its 12 triangles, a sphere as an icosphere of 1280, a capsule as the shipped pebble (1280, a
// rounded irregular form) and a cylinder as the shipped bowl (2304, concave and open, its wall 1.2-1.9 mm thick at
// these sizes) when `bowls` and the object stands still, else as the pebble again (a dynamic mesh must be closed).
// The meshes go through the same files and loader a user's do (common/mesh/mesh_body.h), written to a temporary
// folder.

#include "common/mesh/mesh_body.h"
#include "tests/support/ghost_score.h"
#include "tests/support/mesh_shapes.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace impetus::test {

// `scene` with each object's shape replaced by a mesh as above.
inline Scene as_meshes(Scene scene, bool bowls) {
  // Names formatted, not appended: GCC 12 reports a false -Wrestrict on appending to a string.
  char name[64];
  std::snprintf(name, sizeof name, "impetus_mesh_clutter_%d", static_cast<int>(getpid()));
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(folder);
  const std::string shipped = std::string(IMPETUS_SOURCE_DIR) + "/scenes/meshes/";
  // A shipped mesh scaled so that the ball about its centre that holds it has `radius_m`.
  const auto scaled = [](const std::string& path, double radius_m, bool dynamic) {
    const double unit_radius_m = MeshBody::load(path, Eigen::Vector3d::Ones(), false).shape().radius_m;
    return MeshBody::load(path, Eigen::Vector3d::Constant(radius_m / unit_radius_m), dynamic).shape();
  };
  int written = 0;
  const auto from_mesh = [&](const TriangleMesh& mesh, bool dynamic) {
    std::snprintf(name, sizeof name, "m%d.obj", written++);
    const std::string path = (folder / name).string();
    write_obj(mesh, path);
    return MeshBody::load(path, Eigen::Vector3d::Ones(), dynamic).shape();
  };
  for (SceneObject& object : scene.objects) {
    const Shape& shape = object.shape;
    const double holding_m = world_bounds(shape, BodyPose{}).sizes().norm() / 2.0;
    switch (shape.kind) {
      case ShapeKind::box:
        object.shape = from_mesh(box_mesh(to_eigen(shape.box_size_m)), object.dynamic);
        break;
      case ShapeKind::sphere:
        object.shape = from_mesh(icosphere(shape.radius_m, 3), object.dynamic);
        break;
      case ShapeKind::cylinder:
        object.shape = object.dynamic || !bowls ? scaled(shipped + "pebble.obj", holding_m, object.dynamic)
                                                : scaled(shipped + "bowl.obj", holding_m, false);
        break;
      default:
        object.shape = scaled(shipped + "pebble.obj", holding_m, object.dynamic);
        break;
    }
  }
  return scene;
}

}  // namespace impetus::test
