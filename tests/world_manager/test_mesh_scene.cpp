// SPDX-License-Identifier: Apache-2.0
// Scene objects of shape "mesh": the file beside the scene, its scale, mass and centre of mass from the mesh, and
// errors that name the scene, the key and what is wrong with the file.

#include "common/shape/shape.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"
#include "common/tool/tool_block.h"
#include "world_test_support.h"
#include "tests/support/mesh_shapes.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace impetus {
namespace {

using Eigen::Vector3d;
using nlohmann::json;

std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("impetus-mesh-scene-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "parts");
  return dir;
}

json mesh_object(const std::string& file, bool dynamic) {
  json object{{"name", "part"}, {"shape", "mesh"}, {"file", file}, {"dynamic", dynamic},
              {"position_m", {0.0, 0.0, 0.1}}};
  if (dynamic) object["density_kgpm3"] = 1000.0;
  return object;
}

Scene load(const std::filesystem::path& dir, const json& object) {
  std::ofstream(dir / "scene.json") << json{{"objects", {object}}}.dump();
  return load_scene((dir / "scene.json").string());
}

std::string error_of(const std::filesystem::path& dir, const json& object) {
  try {
    load(dir, object);
  } catch (const SceneError& error) {
    return error.what();
  }
  return "no error";
}

TEST_CASE("a mesh object: its file beside the scene, scaled, its mass and inertia from the mesh") {
  const std::filesystem::path dir = fresh_dir("ok");
  // A 2 × 1 × 1 cm box whose centre lies 3 cm along x from the file's origin, in millimetres in the file.
  test::write_obj(test::box_mesh(Vector3d(20, 10, 10), Vector3d(30, 0, 0)), (dir / "parts/box.obj").string());
  json object = mesh_object("parts/box.obj", true);
  object["scale"] = 0.001;
  const Scene scene = load(dir, object);
  const Shape& shape = scene.objects[0].shape;
  CHECK(shape.kind == ShapeKind::mesh);
  CHECK(shape.mesh_hash != 0);
  CHECK(volume_m3(shape) == Approx(2e-6).epsilon(1e-9));
  CHECK(scene.objects[0].mass_kg == Approx(2e-3).epsilon(1e-9));  // 1000 kg/m³ × 2 cm³
  // The body frame is centred on the centre of mass, not on the file's origin.
  CHECK(shape.box_size_m[0] == Approx(0.02).epsilon(1e-12));
  CHECK(shape.radius_m == Approx(Vector3d(0.01, 0.005, 0.005).norm()).epsilon(1e-12));
  const SurfacePoint top = nearest_surface_point_body(shape, Vector3d(0.0, 0.0, 0.02));
  CHECK(top.point_m.z() == Approx(0.005).epsilon(1e-12));
  CHECK(top.signed_distance_m == Approx(0.015).epsilon(1e-12));
  // A solid box's inertia: m (b² + c²) / 12 about x.
  CHECK(inertia_kgm2(shape, 1.0)(0, 0) == Approx((0.01 * 0.01 + 0.01 * 0.01) / 12.0).epsilon(1e-9));
  CHECK(inertia_kgm2(shape, 1.0)(1, 1) == Approx((0.02 * 0.02 + 0.01 * 0.01) / 12.0).epsilon(1e-9));
  // Scaled per axis, the same file is another shape (another hash).
  object["scale"] = {0.001, 0.002, 0.001};
  const Scene stretched = load(dir, object);
  CHECK(stretched.objects[0].shape.mesh_hash != shape.mesh_hash);
  CHECK(volume_m3(stretched.objects[0].shape) == Approx(4e-6).epsilon(1e-9));
}

TEST_CASE("scene error: a mesh file missing, unreadable, open for a dynamic body, or scaled out of range") {
  const std::filesystem::path dir = fresh_dir("errors");
  std::string message = error_of(dir, mesh_object("parts/none.obj", false));
  INFO(message);
  CHECK(message.find("scene.json: /objects/0/file:") != std::string::npos);
  CHECK(message.find("none.obj") != std::string::npos);

  std::ofstream(dir / "parts/garbage.obj") << "this is not a mesh\n";
  message = error_of(dir, mesh_object("parts/garbage.obj", false));
  CHECK(message.find("/objects/0/file:") != std::string::npos);
  CHECK(message.find("garbage.obj") != std::string::npos);

  // An open mesh (a box without its top) may be static, not dynamic.
  TriangleMesh open = test::box_mesh(Vector3d(0.02, 0.02, 0.02));
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  test::write_obj(open, (dir / "parts/open.obj").string());
  CHECK_NOTHROW(load(dir, mesh_object("parts/open.obj", false)));
  message = error_of(dir, mesh_object("parts/open.obj", true));
  CHECK(message.find("/objects/0/file:") != std::string::npos);
  CHECK(message.find("open") != std::string::npos);

  test::write_obj(test::box_mesh(Vector3d(0.02, 0.02, 0.02)), (dir / "parts/box.obj").string());
  json scaled = mesh_object("parts/box.obj", false);
  scaled["scale"] = 0.0;
  CHECK(error_of(dir, scaled).find("/objects/0/scale:") != std::string::npos);
  scaled["scale"] = {1.0, 1.0};
  CHECK(error_of(dir, scaled).find("/objects/0/scale:") != std::string::npos);
  json unknown = mesh_object("parts/box.obj", false);
  unknown["size_m"] = {0.1, 0.1, 0.1};  // a box's key
  CHECK(error_of(dir, unknown).find("size_m") != std::string::npos);
}

TEST_CASE("a mesh tool: a small convex mesh beside the scene is a tool, weighed from its volume, and others are "
          "refused") {
  const std::filesystem::path dir = fresh_dir("tool");
  test::write_obj(test::box_mesh(Vector3d(0.01, 0.01, 0.04)), (dir / "parts/peg.obj").string());
  test::write_obj(test::icosphere(0.01, 2), (dir / "parts/ball.obj").string());  // 162 corners
  TriangleMesh dented = test::icosphere(0.01, 0);                              // 12 corners, one pushed in
  dented.vertices_m[0] *= 0.3;  // below its five neighbours (at 0.447 of the radius): a dent
  test::write_obj(dented, (dir / "parts/dented.obj").string());
  const auto scene_with_tool = [&](const std::string& file) {
    const json tool{{"shape", "mesh"}, {"file", file}, {"density_kgpm3", 1000.0}, {"position_m", {0.0, 0.0, -0.03}}};
    std::ofstream(dir / "scene.json") << json{{"objects", json::array()}, {"tool", tool}}.dump();
    return (dir / "scene.json").string();
  };
  const Scene scene = load_scene(scene_with_tool("parts/peg.obj"));
  REQUIRE(scene.tool.has_value());
  CHECK(scene.tool->shape.shape.kind == ShapeKind::mesh);
  CHECK(scene.tool->shape.mass_kg == Approx(1000.0 * 0.01 * 0.01 * 0.04).epsilon(1e-6));  // 4 g
  CHECK(scene.tool->reach_m == Approx(0.03 + std::sqrt(0.005 * 0.005 * 2 + 0.02 * 0.02)).epsilon(1e-6));
  // The haptic controller reads the same block (--tool-from), the mesh with it.
  const std::optional<ToolBlock> read = load_scene_tool(scene_with_tool("parts/peg.obj"));
  REQUIRE(read.has_value());
  CHECK(read->shape.shape.mesh_hash == scene.tool->shape.shape.mesh_hash);
  for (const char* refused : {"parts/ball.obj", "parts/dented.obj"}) {
    CAPTURE(refused);
    std::string message = "no error";
    try {
      load_scene(scene_with_tool(refused));
    } catch (const SceneError& error) {
      message = error.what();
    }
    CHECK_THAT(message, Catch::Contains("/tool/file") && Catch::Contains("convex body with at most 32 corners"));
  }
}

}  // namespace
}  // namespace impetus
