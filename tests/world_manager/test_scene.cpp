// SPDX-License-Identifier: Apache-2.0
#include "world_manager/scene.h"
#include "world_manager/engine/engine_registry.h"
#include "world_test_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <numbers>
#include <fstream>
#include <limits>
#include <string>

using impetus::Scene;
using impetus::SceneError;
using nlohmann::json;

namespace {

json cube() {
  return json{{"name", "cube"},         {"shape", "box"},  {"size_m", {0.05, 0.05, 0.05}},
              {"dynamic", true},        {"mass_kg", 1.0},  {"position_m", {0.03, 0.0, 0.025}}};
}

json scene_with(const json& object) { return json{{"objects", {object}}}; }

// The error must name the file and the JSON path of the offending field, and say why.
void require_error(const json& document, const std::string& pointer, const std::string& reason) {
  try {
    impetus::parse_scene(document, "bad.json");
    FAIL("expected SceneError for " << pointer);
  } catch (const SceneError& error) {
    const std::string message = error.what();
    INFO(message);
    CHECK(message.rfind("bad.json: " + pointer + ":", 0) == 0);
    CHECK(message.find(reason) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("a minimal scene gets the documented defaults") {
  const Scene scene = impetus::parse_scene(scene_with(cube()), "ok.json");
  REQUIRE(scene.objects.size() == 1);
  CHECK(scene.gravity_mps2[2] == -9.81);
  CHECK(scene.floor.present);
  CHECK(scene.floor.height_m == 0.0);
  CHECK(scene.physics.world_rate_hz == 20.0);
  CHECK(scene.haptic.stiffness_Npm == 2000.0);
  CHECK(scene.objects[0].mass_kg == 1.0);
  CHECK(scene.objects[0].orientation_wxyz[0] == 1.0);
  CHECK(scene.floor_object_id() == 1);
}

TEST_CASE("density gives mass from the shape's volume") {
  json sphere{{"name", "s"}, {"shape", "sphere"}, {"radius_m", 0.1}, {"dynamic", true},
              {"density_kgpm3", 1000.0}, {"position_m", {0, 0, 1}}};
  const Scene scene = impetus::parse_scene(scene_with(sphere), "ok.json");
  CHECK(scene.objects[0].mass_kg == Approx(1000.0 * 4.0 / 3.0 * std::numbers::pi * 1e-3).epsilon(1e-12));
}

TEST_CASE("shipped scenes load") {
  for (const char* file : {"tap.json", "spheres.json", "stack.json", "meshes.json"}) {
    INFO(file);
    const Scene scene = impetus::load_scene(impetus::test::scene_path(file));
    CHECK_FALSE(scene.objects.empty());
  }
  const Scene spheres = impetus::load_scene(impetus::test::scene_path("spheres.json"));
  CHECK(spheres.objects.size() >= 20);  // paper §5: more than 20 movable spheres
  const Scene tap = impetus::load_scene(impetus::test::scene_path("tap.json"));
  CHECK(tap.objects[0].mass_kg == 1.0);  // paper §4.2.2: a cube of 1 kg
}

TEST_CASE("scene error: unknown key names the key") {
  json object = cube();
  object["colour"] = "red";
  require_error(scene_with(object), "/objects/0/colour", "unknown key");
  require_error(json{{"objects", json::array()}, {"physcs", json::object()}}, "/physcs", "unknown key");
}

TEST_CASE("scene error: a key of another shape is unknown") {
  json object = cube();
  object["radius_m"] = 0.1;
  require_error(scene_with(object), "/objects/0/radius_m", "unknown key");
}

TEST_CASE("scene error: missing field") {
  json object = cube();
  object.erase("position_m");
  require_error(scene_with(object), "/objects/0/position_m", "missing");
  require_error(json::object(), "/objects", "missing");
  json no_size = cube();
  no_size.erase("size_m");
  require_error(scene_with(no_size), "/objects/0/size_m", "missing");
  json no_mass = cube();
  no_mass.erase("mass_kg");
  require_error(scene_with(no_mass), "/objects/0/mass_kg", "missing");
}

TEST_CASE("scene error: wrong type") {
  json object = cube();
  object["mass_kg"] = "heavy";
  require_error(scene_with(object), "/objects/0/mass_kg", "expected a number");
  json flag = cube();
  flag["dynamic"] = 1;
  require_error(scene_with(flag), "/objects/0/dynamic", "expected true or false");
  json short_position = cube();
  short_position["position_m"] = {0.0, 0.0};
  require_error(scene_with(short_position), "/objects/0/position_m", "array of 3");
}

TEST_CASE("scene error: negative or zero mass") {
  json object = cube();
  object["mass_kg"] = -1.0;
  require_error(scene_with(object), "/objects/0/mass_kg", "between 1e-06 and");
  object["mass_kg"] = 0.0;
  require_error(scene_with(object), "/objects/0/mass_kg", "between 1e-06 and");
}

TEST_CASE("scene error: mass and density together") {
  json object = cube();
  object["density_kgpm3"] = 1000.0;
  require_error(scene_with(object), "/objects/0/density_kgpm3", "not both");
}

TEST_CASE("scene error: zero or negative size") {
  json object = cube();
  object["size_m"] = {0.05, 0.0, 0.05};
  require_error(scene_with(object), "/objects/0/size_m/1", "between 0.0001 and");
  json sphere{{"name", "s"}, {"shape", "sphere"}, {"radius_m", -0.1}, {"dynamic", false}, {"position_m", {0, 0, 0}}};
  require_error(scene_with(sphere), "/objects/0/radius_m", "between 0.0001 and");
}

TEST_CASE("scene error: non-unit quaternion") {
  json object = cube();
  object["orientation_wxyz"] = {1.0, 0.1, 0.0, 0.0};
  require_error(scene_with(object), "/objects/0/orientation_wxyz", "unit");
}

TEST_CASE("scene error: non-finite number") {
  // JSON text cannot carry NaN, but a document built in code can.
  json object = cube();
  object["position_m"] = {0.0, std::numeric_limits<double>::quiet_NaN(), 0.0};
  require_error(scene_with(object), "/objects/0/position_m/1", "finite");
  json rate{{"objects", json::array()}, {"physics", {{"world_rate_hz", std::numeric_limits<double>::infinity()}}}};
  require_error(rate, "/physics/world_rate_hz", "finite");
}

TEST_CASE("scene error: a number too large for a double names its line and column") {
  const std::string text = "{\"description\": \"1e999\",\n  \"gravity_mps2\": [0, 0,\n    1e999]}";
  try {
    impetus::parse_scene_text(text, "huge.json");
    FAIL("a number out of range was accepted");
  } catch (const impetus::SceneError& error) {
    CHECK_THAT(error.what(), Catch::Contains("huge.json") && Catch::Contains("line 3, column 5") &&
                                 Catch::Contains("1e999"));
  }
}

TEST_CASE("scene error: duplicate name") {
  json second = cube();
  second["position_m"] = {0.2, 0.0, 0.025};
  require_error(json{{"objects", {cube(), second}}}, "/objects/1/name", "duplicate");
}

TEST_CASE("scene error: dynamic friction above static friction") {
  json object = cube();
  object["static_friction"] = 0.2;
  object["dynamic_friction"] = 0.3;
  require_error(scene_with(object), "/objects/0/dynamic_friction", "must not exceed");
}

TEST_CASE("scene error: restitution outside [0, 1]") {
  json object = cube();
  object["restitution"] = 1.5;
  require_error(scene_with(object), "/objects/0/restitution", "[0, 1]");
}

TEST_CASE("scene error: unknown shape") {
  json object = cube();
  object["shape"] = "torus";
  require_error(scene_with(object), "/objects/0/shape", "unknown shape");
}

TEST_CASE("scene error: static object with a mass or a velocity") {
  json object = cube();
  object["dynamic"] = false;
  require_error(scene_with(object), "/objects/0/mass_kg", "static");
}

TEST_CASE("scene error: bad physics settings") {
  require_error(json{{"objects", json::array()}, {"physics", {{"substeps", 0}}}}, "/physics/substeps", "from 1 to");
  require_error(json{{"objects", json::array()}, {"physics", {{"substeps", 2.5}}}}, "/physics/substeps", "whole");
  require_error(json{{"objects", json::array()}, {"haptic", {{"stiffness_Npm", -1}}}}, "/haptic/stiffness_Npm",
                "positive");
  require_error(json{{"objects", json::array()}, {"physics", {{"ode", {{"solver", "magic"}}}}}},
                "/physics/ode/solver", "\"quickstep\" or \"direct\"");
  require_error(json{{"objects", json::array()}, {"physics", {{"ode", {{"max_correcting_velocity_mps", 0}}}}}},
                "/physics/ode/max_correcting_velocity_mps", "positive");
  require_error(json{{"objects", json::array()}, {"physics", {{"speculative_contacts", 1}}}},
                "/physics/speculative_contacts", "true or false");
}

TEST_CASE("speculative contacts are on unless the scene turns them off") {
  CHECK(impetus::parse_scene(json{{"objects", json::array()}}, "test.json").physics.speculative_contacts);
  const json document{{"objects", json::array()}, {"physics", {{"speculative_contacts", false}}}};
  CHECK_FALSE(impetus::parse_scene(document, "test.json").physics.speculative_contacts);
}

TEST_CASE("the penetration correction is uncapped unless the scene caps it") {
  CHECK(std::isinf(impetus::parse_scene(json{{"objects", json::array()}}, "test.json").physics.ode
                       .max_correcting_velocity_mps));
  const json document{{"objects", json::array()}, {"physics", {{"ode", {{"max_correcting_velocity_mps", 0.005}}}}}};
  CHECK(impetus::parse_scene(document, "test.json").physics.ode.max_correcting_velocity_mps == 0.005);
}

TEST_CASE("a contact takes ODE's ERP and CFM as they are, or a spring and damper that agree with them at 5 ms") {
  const impetus::PhysicsParams defaults = impetus::parse_scene(json{{"objects", json::array()}}, "t.json").physics;
  CHECK_FALSE(defaults.contact_spring());
  for (const double h_s : {1e-4, 5e-3, 0.01}) {
    CHECK(defaults.erp_at(h_s) == 0.2);
    CHECK(defaults.cfm_at(h_s) == 1e-5);
  }
  // Either field makes every contact a spring and a damper; the other is the one that agrees with ODE's numbers at
  // 20 Hz × 10 substeps, exactly.
  const json stiffness_only{{"objects", json::array()}, {"physics", {{"contact_stiffness_Npm", 4e6}}}};
  const impetus::PhysicsParams spring = impetus::parse_scene(stiffness_only, "t.json").physics;
  REQUIRE(spring.contact_spring());
  CHECK(spring.erp_at(0.05 / 10) == 0.2);
  CHECK(spring.cfm_at(0.05 / 10) == 1e-5);
  // The same spring at any substep: ERP/(h·CFM) = k and (1 − ERP)/CFM = c.
  for (const double h_s : {1e-4, 1.25e-3, 2e-3, 0.01}) {
    INFO("substep " << h_s << " s");
    CHECK(spring.erp_at(h_s) / (h_s * spring.cfm_at(h_s)) == Approx(4e6).epsilon(1e-12));
    CHECK((1.0 - spring.erp_at(h_s)) / spring.cfm_at(h_s) == Approx(8e4).epsilon(1e-9));
  }
  const json undamped{{"objects", json::array()},
                      {"physics", {{"contact_stiffness_Npm", 1e5}, {"contact_damping_Nspm", 0}}}};
  const impetus::PhysicsParams rigid = impetus::parse_scene(undamped, "t.json").physics;
  CHECK(rigid.erp_at(1e-3) == 1.0);  // no damper: the whole penetration is corrected in one substep
  CHECK(rigid.cfm_at(1e-3) == Approx(1e-2));
  const json own{{"objects", json::array()}, {"physics", {{"ode", {{"erp", 0.5}, {"cfm", 0.0}}}}}};
  const impetus::PhysicsParams ode = impetus::parse_scene(own, "t.json").physics;
  CHECK(ode.erp_at(1e-2) == 0.5);
  CHECK(ode.cfm_at(1e-3) == 0.0);
}

TEST_CASE("scene error: both contact models at once, or a contact softer than 1 N/m") {
  require_error(
      json{{"objects", json::array()}, {"physics", {{"ode", {{"erp", 0.2}}}, {"contact_stiffness_Npm", 1e6}}}},
      "/physics/ode/erp", "not both");
  require_error(
      json{{"objects", json::array()}, {"physics", {{"ode", {{"cfm", 1e-5}}}, {"contact_damping_Nspm", 1e4}}}},
      "/physics/ode/cfm", "not both");
  require_error(json{{"objects", json::array()}, {"physics", {{"contact_stiffness_Npm", 0.5}}}},
                "/physics/contact_stiffness_Npm", "N/m");
  require_error(json{{"objects", json::array()}, {"physics", {{"contact_damping_Nspm", -1}}}},
                "/physics/contact_damping_Nspm", "N·s/m");
}

TEST_CASE("the direct solver is chosen by the scene and QuickStep is the default") {
  const json document{{"objects", json::array()}, {"physics", {{"ode", {{"solver", "direct"}}}}}};
  CHECK(impetus::parse_scene(document, "test.json").physics.ode.solver == impetus::OdeParams::Solver::direct);
  CHECK(impetus::parse_scene(json{{"objects", json::array()}}, "test.json").physics.ode.solver ==
        impetus::OdeParams::Solver::quickstep);
}

TEST_CASE("the engine is chosen by name from the registry, ODE by default, and its own settings live in its block") {
  CHECK(impetus::parse_scene(json{{"objects", json::array()}}, "test.json").physics.engine == "ode");
  const json chosen{{"objects", json::array()}, {"physics", {{"engine", "ode"}, {"ode", {{"erp", 0.3}}}}}};
  CHECK(impetus::parse_scene(chosen, "test.json").physics.ode.erp == 0.3);
  // An unknown engine names the known ones.
  require_error(json{{"objects", json::array()}, {"physics", {{"engine", "havok"}}}}, "/physics/engine",
                "unknown engine, expected ode");
  // An engine's own key at the top of the physics block says where it now goes.
  require_error(json{{"objects", json::array()}, {"physics", {{"solver_iterations", 30}}}},
                "/physics/solver_iterations", "\"physics\": {\"ode\": {\"solver_iterations\": ...}}");
  // A block for an engine the registry does not hold is an unknown key, and so is a key the engine does not have.
  require_error(json{{"objects", json::array()}, {"physics", {{"mujoco", json::object()}}}}, "/physics/mujoco",
                "unknown key");
  require_error(json{{"objects", json::array()}, {"physics", {{"ode", {{"iterations", 30}}}}}},
                "/physics/ode/iterations", "unknown key");
  // The registry builds what the scene names, and refuses what it does not hold.
  impetus::Scene scene = impetus::parse_scene(json{{"objects", json::array()}}, "test.json");
  impetus::prepare_engines();
  CHECK(impetus::make_engine(scene) != nullptr);
  scene.physics.engine = "havok";
  CHECK_THROWS_AS(impetus::make_engine(scene), impetus::SceneError);
}

TEST_CASE("scene error: the message echoes the offending value") {
  json object = cube();
  object["mass_kg"] = -3.5;
  try {
    impetus::parse_scene(scene_with(object), "bad.json");
    FAIL("expected SceneError");
  } catch (const SceneError& error) {
    CHECK(std::string(error.what()).find("(got -3.5)") != std::string::npos);
  }
}

TEST_CASE("scene error: unreadable file and invalid JSON name the file") {
  CHECK_THROWS_WITH(impetus::load_scene("/nonexistent/scene.json"), Catch::Contains("/nonexistent/scene.json"));
  const std::string path = std::string(IMPETUS_BINARY_DIR) + "/broken_scene_for_test.json";
  std::ofstream(path) << "{\"objects\": [";
  CHECK_THROWS_WITH(impetus::load_scene(path), Catch::Contains(path) && Catch::Contains("not valid JSON"));
}

namespace {

// The scene with one value replaced, at a JSON pointer.
json with_value(json document, const std::string& pointer, const json& value) {
  document[json::json_pointer(pointer)] = value;
  return document;
}

}  // namespace

TEST_CASE("scene error: finite values beyond what the engine can simulate name the field and the range") {
  // Each of these passed the parser before and then aborted ODE, hung the world or overflowed an integer.
  const json base = scene_with(cube());
  struct Case {
    std::string pointer;
    json value;
    std::string reason;
  };
  const Case cases[] = {
      {"/objects/0/position_m/0", 1e12, "between -10000 and 10000 m"},
      {"/objects/0/size_m/1", 1e6, "between 0.0001 and 1000 m"},
      {"/objects/0/size_m/2", 1e-9, "between 0.0001 and 1000 m"},
      {"/objects/0/mass_kg", 1e30, "between 1e-06 and 1e+06 kg"},
      {"/objects/0/linear_velocity_mps", json{1e12, 0, 0}, "at most 1000 m/s"},
      {"/objects/0/angular_velocity_radps", json{0, 1e12, 0}, "at most 10000 rad/s"},
      {"/objects/0/static_friction", 1e30, "between 0 and 100"},
      {"/gravity_mps2", json{0, 0, -1e30}, "at most 1000 m/s"},
      {"/floor/height_m", 1e12, "between -10000 and 10000 m"},
      {"/physics/substeps", 1000000, "from 1 to 10000"},
      {"/physics/ode/solver_iterations", 1000000, "from 1 to 10000"},
      {"/physics/substeps", 1e300, "whole number"},
      {"/physics/world_rate_hz", 1e30, "between 0.1 and 10000 Hz"},
      {"/physics/world_rate_hz", 1e-300, "between 0.1 and 10000 Hz"},
      {"/physics/ode/cfm", 1e30, "between 0 and 1"},
      {"/haptic/stiffness_Npm", 1e30, "at most 1e+06 N/m"},
      {"/haptic/reach_radius_m", 1e30, "at most 10 m"},
  };
  for (const Case& test_case : cases) {
    INFO(test_case.pointer << " = " << test_case.value.dump());
    require_error(with_value(base, test_case.pointer, test_case.value), test_case.pointer, test_case.reason);
  }
  // A density that is fine alone but gives a mass out of range.
  json dense = cube();
  dense.erase("mass_kg");
  dense["density_kgpm3"] = 1e300;
  require_error(scene_with(dense), "/objects/0/density_kgpm3", "between 1e-06 and 1e+06 kg");
}

TEST_CASE("scene error: more objects than the stated limit is refused before anything is built") {
  json objects = json::array();
  for (std::size_t i = 0; i <= impetus::SceneLimits::kMaxObjects; ++i) {
    json object = cube();
    object["name"] = std::to_string(i);
    objects.push_back(object);
  }
  require_error(json{{"objects", objects}}, "/objects", "at most 10000 objects");
}

namespace {

// The message parse_scene_text throws for `text` ("" if it accepts it).
std::string text_error(const std::string& text, const std::string& name) {
  try {
    impetus::parse_scene_text(text, name);
  } catch (const SceneError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_CASE("scene error: deep nesting and huge tokens give a short message without recursion") {
  // 10^6 levels: dumping the value to quote it used to recurse once per level and overflow the stack.
  const std::size_t depth = 1'000'000;
  std::string deep = "{\"objects\": [{\"name\": ";
  deep.append(depth, '[').append(depth, ']').append("}]}");
  // A 50 MB bad string: nlohmann quotes the whole token in its message.
  std::string huge = "{\"objects\": \"";
  huge.append(50'000'000, 'a').append("\x01\"}");
  // A 10 MB unknown key.
  std::string key = "{\"";
  key.append(10'000'000, 'k').append("\": 1, \"objects\": []}");
  const struct {
    const std::string& text;
    const char* name;
    const char* expected;
  } cases[] = {{deep, "deep.json", "/objects/0"}, {huge, "huge.json", "not valid JSON"}, {key, "key.json", "unknown key"}};
  for (const auto& test_case : cases) {
    const std::string message = text_error(test_case.text, test_case.name);
    INFO(message.substr(0, 300));
    CHECK(message.size() < 600);
    CHECK_THAT(message, Catch::Contains(test_case.name) && Catch::Contains(test_case.expected));
  }
}

TEST_CASE("a tool block is parsed, its reach widens the world's, and bad values name their field") {
  const Scene scene = impetus::load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/peg_in_hole.json");
  REQUIRE(scene.tool);
  CHECK(scene.tool->shape.shape.kind == impetus::ShapeKind::box);
  CHECK(scene.tool->shape.placement.position_m.z() == Approx(-0.03));
  CHECK(scene.tool->coupling.stiffness_Npm == 2000.0);
  // The peg's farthest corner is 3 cm + √(5² + 5² + 20²) mm from the grip; the reach is that plus a finger's 5 cm.
  CHECK(scene.tool->reach_m == Approx(0.03 + std::sqrt(2 * 0.005 * 0.005 + 0.02 * 0.02)));
  CHECK(scene.haptic.reach_radius_m == Approx(0.05 + scene.tool->reach_m));
  const impetus::Scene none = impetus::parse_scene(scene_with(cube()), "ok.json");
  CHECK_FALSE(none.tool);

  const auto with_tool = [](const json& tool) {
    json document = scene_with(cube());
    document["tool"] = tool;
    return document;
  };
  const json ball = {{"shape", "sphere"}, {"radius_m", 0.01}};
  require_error(with_tool({{"shape", "mesh"}, {"file", "x.obj"}}), "/tool/file", "cannot open the mesh file");
  require_error(with_tool({{"radius_m", 0.01}}), "/tool/shape", "missing");
  json bad = ball;
  bad["stiffness_Npm"] = -1;
  require_error(with_tool(bad), "/tool/stiffness_Npm", "");
  bad = ball;
  bad["orientation_wxyz"] = {1, 1, 0, 0};
  require_error(with_tool(bad), "/tool/orientation_wxyz", "unit");
  bad = ball;
  bad["radius"] = 2;
  require_error(with_tool(bad), "/tool/radius", "unknown key");
  bad = ball;
  bad["position_m"] = {0, 0, -2};
  require_error(with_tool(bad), "/tool/position_m", "");
  require_error(with_tool({{"shape", "box"}, {"size_m", {20, 0.01, 0.01}}}), "/tool", "reaches 10 m from its grip");
  json capsule = {{"shape", "capsule"}, {"radius_m", 0.01}, {"length_m", 0.1}, {"position_m", {0, 0, -0.05}}};
  json document = with_tool(capsule);
  document["haptic"] = {{"reach_radius_m", 0.05}};
  require_error(document, "/haptic/reach_radius_m", "must cover the tool");
  document["tool"] = ball;
  CHECK(impetus::parse_scene(document, "ok.json").haptic.reach_radius_m == 0.05);  // given and enough: kept

  // Its mass, or density × volume, weighs it under the scene's gravity; none given: weightless.
  CHECK(impetus::parse_scene(with_tool(ball), "ok.json").tool->shape.weight_N.isZero());
  json heavy = ball;
  heavy["mass_kg"] = 0.2;
  json moon = with_tool(heavy);
  moon["gravity_mps2"] = {0, 0, -1.62};
  const impetus::SceneTool weighed = *impetus::parse_scene(moon, "ok.json").tool;
  CHECK(weighed.shape.mass_kg == 0.2);
  CHECK(weighed.shape.weight_N.z() == Approx(-0.324));
  heavy = ball;
  heavy["density_kgpm3"] = 1000.0;
  CHECK(impetus::parse_scene(with_tool(heavy), "ok.json").tool->shape.mass_kg ==
        Approx(1000.0 * 4.0 / 3.0 * M_PI * 1e-6));
  heavy["mass_kg"] = 0.1;
  require_error(with_tool(heavy), "/tool/density_kgpm3", "not both");
  heavy = ball;
  heavy["mass_kg"] = 2.0;  // 19.6 N, over the default 10 N
  require_error(with_tool(heavy), "/tool/mass_kg", "could not hold it up");
  heavy["mass_kg"] = 0.5;
  heavy["position_m"] = {0.2, 0, 0};  // 0.98 N·m at most, over the default 0.5 N·m
  require_error(with_tool(heavy), "/tool/mass_kg", "could not hold it level");
  heavy["mass_kg"] = -0.1;
  require_error(with_tool(heavy), "/tool/mass_kg", "");
}
