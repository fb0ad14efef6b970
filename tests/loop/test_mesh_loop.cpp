// SPDX-License-Identifier: Apache-2.0
// Meshes in the whole loop (world, haptic side, device in one process): a mesh body behaves as the primitive of the
// same shape, is felt where it is, and what the haptic side renders on it is what the world applies.

#include "loop/in_process_trial.h"
#include "tests/integration/trial_support.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace impetus {
namespace {

const std::string kSceneDir = std::string(IMPETUS_SOURCE_DIR) + "/scenes";

// The tap scene with its cube made of the 12-triangle mesh of the same size and mass.
std::string tap_with_mesh_cube() {
  nlohmann::json scene = nlohmann::json::parse(test::read_text(kSceneDir + "/tap.json"));
  nlohmann::json& cube = scene["objects"][0];
  cube["shape"] = "mesh";
  cube.erase("size_m");
  cube["file"] = kSceneDir + "/meshes/cube.obj";
  return scene.dump();
}

nlohmann::json tap(const std::string& scene_text, Coupling coupling, const std::string& name) {
  InProcessTrialOptions options;
  options.scene_path = kSceneDir + "/tap.json";
  options.scene_text = scene_text;
  options.trajectory = "tap";
  options.coupling = coupling;
  options.duration_s = 2.0;
  options.out_dir = test::out_dir(name);
  return run_in_process_trial(options);
}

TEST_CASE("a mesh cube is tapped as the primitive box is, under every coupling, and gets the impulse rendered on it") {
  for (const Coupling coupling : {Coupling::impulse, Coupling::position, Coupling::local}) {
    INFO(to_string(coupling));
    const std::string name = to_string(coupling);
    const nlohmann::json box = tap("", coupling, "mesh-tap-box-" + name);
    const nlohmann::json mesh = tap(tap_with_mesh_cube(), coupling, "mesh-tap-mesh-" + name);
    const double box_x = box["objects"]["cube"]["position"][0].get<double>();
    const double mesh_x = mesh["objects"]["cube"]["position"][0].get<double>();
    // The same finger, the same planes (a box face and the mesh's face are the same plane), the same contacts with
    // the floor (ODE's trimesh collider and its box collider both put them at the four bottom corners): the two
    // differ by rounding in the colliders only, far below the 0.1 mm a person could see.
    CHECK(std::abs(mesh_x - box_x) < 1e-4);
    CHECK(mesh_x - 0.03 > 0.1);  // it slid
    // Position coupling applies its own penalty force, not the impulse.
    if (coupling != Coupling::position) CHECK(test::ledger_gap(mesh, "0") <= 1e-12);
  }
}

TEST_CASE("the shipped mesh scene: the pebble rests on the floor, the cube is tapped along, nothing escapes") {
  InProcessTrialOptions options;
  options.scene_path = kSceneDir + "/meshes.json";
  options.trajectory = "tap";
  options.coupling = Coupling::local;
  options.duration_s = 3.0;
  options.out_dir = test::out_dir("mesh-scene");
  const nlohmann::json summary = run_in_process_trial(options);
  CHECK(summary["world"]["escaped_objects"].empty());
  // The pebble's lowest point lies 19.9 mm below its centre of mass (scripts/make_meshes.py's pebble): resting on
  // the floor, its centre stays there, give or take the contact's give (ODE's soft contact sinks well under 1 mm).
  const nlohmann::json& pebble = summary["objects"]["pebble"]["position"];
  CHECK(pebble[2].get<double>() == Approx(0.0199).margin(1e-3));
  CHECK(std::abs(pebble[0].get<double>() - 0.03) < 2e-3);
  CHECK(std::abs(pebble[1].get<double>() - 0.12) < 2e-3);
  CHECK(summary["objects"]["cube"]["position"][0].get<double>() > 0.13);  // tapped along, past the bowl's side
}

}  // namespace
}  // namespace impetus
