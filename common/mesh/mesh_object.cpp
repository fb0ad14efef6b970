// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mesh_object.h"

#include "common/mesh/mesh_body.h"
#include "common/runtime/input_error.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

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

std::string scene_folder(const std::string& scene_source) {
  std::error_code not_a_file;
  return std::filesystem::is_regular_file(scene_source, not_a_file)
             ? std::filesystem::path(scene_source).parent_path().string()
             : std::string();
}

std::size_t load_scene_meshes(const std::string& path) {
  const nlohmann::json document = read_scene_document(path);
  const JsonNode root(document, "", path);
  if (!root.has("objects") || !document["objects"].is_array()) return 0;
  const JsonNode objects = root.child("objects");
  const std::string folder = scene_folder(path);
  std::size_t meshes = 0;
  for (std::size_t i = 0; i < document["objects"].size(); ++i) {
    const JsonNode object = objects.element(i);
    if (!object.value().is_object() || !object.has("shape") || object.value()["shape"] != "mesh") continue;
    const bool dynamic = object.has("dynamic") && object.child("dynamic").boolean();
    load_mesh_shape(object, folder, dynamic);
    ++meshes;
  }
  return meshes;
}

}  // namespace impetus
