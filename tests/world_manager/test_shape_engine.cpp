// SPDX-License-Identifier: Apache-2.0
// The shape module and the engine agree on what a body is: the mass properties the engine simulates are the ones
// common/shape/shape.h computes (the summary reports those, and Python's energy bookkeeping uses them).
#include "common/shape/shape.h"
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <string>

TEST_CASE("every engine simulates each shape with the inertia the shape module gives it") {
  using nlohmann::json;
  const json objects = json::array({
      {{"name", "brick"}, {"shape", "box"}, {"size_m", {0.1, 0.2, 0.3}}},
      {{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.05}},
      {{"name", "pill"}, {"shape", "capsule"}, {"radius_m", 0.03}, {"length_m", 0.1}},
      {{"name", "can"}, {"shape", "cylinder"}, {"radius_m", 0.04}, {"length_m", 0.12}},
  });
  json document{{"floor", nullptr}, {"gravity_mps2", {0, 0, 0}}, {"objects", json::array()}};
  for (std::size_t k = 0; k < objects.size(); ++k) {
    json object = objects[k];
    object["dynamic"] = true;
    object["mass_kg"] = 0.5 + static_cast<double>(k);
    object["position_m"] = {0.5 * static_cast<double>(k), 0.0, 0.0};
    document["objects"].push_back(object);
  }
  for (const impetus::EngineEntry& entry : impetus::engine_entries()) {
    document["physics"]["engine"] = std::string(entry.name);
    const impetus::Scene scene = impetus::parse_scene(document, "shapes.json");
    auto world = impetus::test::make_world(scene);
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
      const impetus::SceneObject& object = scene.objects[id];
      INFO(entry.name << ": " << object.name);
      const Eigen::Matrix3d simulated = world->states()[id].inverse_inertia_world.inverse();
      const Eigen::Matrix3d modelled = impetus::inertia_kgm2(object.shape, object.mass_kg);
      CHECK((simulated - modelled).norm() <= 1e-12 * modelled.norm());
      CHECK(world->states()[id].inverse_mass_per_kg == Approx(1.0 / object.mass_kg).epsilon(1e-15));
    }
  }
}
