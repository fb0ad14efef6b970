// SPDX-License-Identifier: Apache-2.0
#include "world_manager/mesh_objects.h"

#include "common/mesh/mesh_body.h"
#include "common/runtime/input_error.h"

#include <filesystem>

namespace impetus {
namespace {

// A scale beyond a thousandfold either way is a unit mistake more likely than a wish (metres read as micrometres).
constexpr double kMinScale = 1e-3;
constexpr double kMaxScale = 1e3;

Eigen::Vector3d parse_scale(const JsonNode& node) {
  if (node.value().is_number()) return Eigen::Vector3d::Constant(node.in_range(kMinScale, kMaxScale, ""));
  const std::array<double, 3> axes = node.numbers<3>();
  for (std::size_t i = 0; i < 3; ++i) node.element(i).in_range(kMinScale, kMaxScale, "");
  return {axes[0], axes[1], axes[2]};
}

}  // namespace

Shape load_mesh_shape(const JsonNode& object, const std::string& scene_dir, bool dynamic) {
  const JsonNode file = object.required("file");
  const std::string name = file.string();
  if (name.empty()) file.fail("a mesh needs a file");
  const std::filesystem::path given(name);
  const std::filesystem::path path =
      given.is_absolute() || scene_dir.empty() ? given : std::filesystem::path(scene_dir) / given;
  const Eigen::Vector3d scale = object.has("scale") ? parse_scale(object.child("scale")) : Eigen::Vector3d::Ones();
  try {
    return MeshBody::load(path.string(), scale, dynamic).shape();
  } catch (const InputError& error) {
    file.fail(error.what());
  }
}

}  // namespace impetus
