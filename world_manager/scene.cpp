// SPDX-License-Identifier: Apache-2.0
#include "world_manager/scene.h"

#include "common/contract/limits.h"
#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"
#include "common/tool/tool_block.h"
#include "common/mesh/mesh_body.h"
#include "common/mesh/mesh_object.h"
#include "world_manager/deform/deformable_surface.h"
#include "world_manager/engine/engine_registry.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <fstream>
#include <span>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

namespace impetus {

namespace {

using nlohmann::json;

using Node = JsonNode;

Material parse_material(const Node& node, Material material) {
  if (node.has("static_friction")) {
    material.static_friction = node.child("static_friction").in_range(0.0, SceneLimits::kMaxFriction, "");
  }
  if (node.has("dynamic_friction")) {
    material.dynamic_friction = node.child("dynamic_friction").in_range(0.0, SceneLimits::kMaxFriction, "");
  } else if (node.has("static_friction")) {
    material.dynamic_friction = material.static_friction;  // one coefficient given: no stick-slip difference
  }
  if (material.dynamic_friction > material.static_friction) {
    const Node offending = node.has("dynamic_friction") ? node.child("dynamic_friction") : node;
    offending.fail("dynamic_friction must not exceed static_friction (" + std::to_string(material.static_friction) +
                   ")");
  }
  if (node.has("restitution")) material.restitution = node.child("restitution").in_unit_interval();
  return material;
}

Floor parse_floor(const Node& node) {
  Floor floor;
  if (node.value().is_null()) {
    floor.present = false;
    return floor;
  }
  node.expect_keys({"height_m", "static_friction", "dynamic_friction", "restitution"});
  if (node.has("height_m")) {
    floor.height_m =
        node.child("height_m").in_range(-SceneLimits::kMaxCoordinate_m, SceneLimits::kMaxCoordinate_m, " m");
  }
  floor.material = parse_material(node, floor.material);
  return floor;
}

// ODE's own keys, now in "physics": {"ode": {...}}; named where they were first given, to say where they went.
constexpr std::string_view kOdeKeys[] = {"solver", "solver_iterations", "erp", "cfm", "max_correcting_velocity_mps"};

PhysicsParams parse_physics(const Node& node) {
  node.expect_object();
  PhysicsParams physics;
  if (node.has("engine")) {
    const Node engine = node.child("engine");
    physics.engine = engine.string();
    if (find_engine(physics.engine) == nullptr) engine.fail("unknown engine, expected " + engine_names());
  }
  for (const std::string_view key : kOdeKeys) {
    if (node.has(key)) {
      node.child(key).fail("an engine's own setting: give it in the engine's block, \"physics\": {\"ode\": {\"" +
                           std::string(key) + "\": ...}}");
    }
  }
  const std::string_view kNeutralKeys[] = {"engine", "world_rate_hz", "substeps", "contact_stiffness_Npm",
                                           "contact_damping_Nspm", "speculative_contacts", "auto_disable", "seed"};
  // Every engine's block may be given, each read by its own engine: a scene says what it needs on each engine (a direct
  // solver for a stack of large mass ratios, say) and keeps it when a run chooses another engine (--engine).
  std::vector<std::string_view> block_keys;
  for (const EngineEntry& entry : engine_entries()) block_keys.push_back(entry.name);
  node.expect_keys({std::span<const std::string_view>(kNeutralKeys), std::span<const std::string_view>(block_keys)});
  if (node.has("world_rate_hz")) {
    physics.world_rate_hz = node.child("world_rate_hz").in_range(limits::kMinWorldRate_Hz, limits::kMaxWorldRate_Hz, " Hz");
  }
  if (node.has("substeps")) physics.substeps = node.child("substeps").positive_int(limits::kMaxSubsteps);
  if (node.has("contact_stiffness_Npm")) {
    physics.contact_stiffness_Npm =
        node.child("contact_stiffness_Npm")
            .in_range(SceneLimits::kMinContactStiffness_Npm, SceneLimits::kMaxContactStiffness_Npm, " N/m");
  }
  if (node.has("contact_damping_Nspm")) {
    physics.contact_damping_Nspm =
        node.child("contact_damping_Nspm").in_range(0.0, SceneLimits::kMaxContactDamping_Nspm, " N·s/m");
  }
  if (node.has("speculative_contacts")) {
    physics.speculative_contacts = node.child("speculative_contacts").boolean();
  }
  if (node.has("auto_disable")) physics.auto_disable = node.child("auto_disable").boolean();
  if (node.has("seed")) {
    const Node seed = node.child("seed");
    if (!seed.value().is_number_unsigned()) seed.fail("expected a non-negative integer");
    physics.seed = seed.value().get<std::uint64_t>();
  }
  // After the neutral keys: an engine's block may depend on them (ODE's ERP and CFM exclude the contact spring).
  // Every block is checked, the chosen engine's or not, so a mistake shows whichever engine runs.
  for (const EngineEntry& entry : engine_entries()) {
    if (!node.has(entry.name)) continue;
    const Node block = node.child(entry.name);
    block.expect_object();
    entry.parse_block(block, physics);
  }
  return physics;
}

HapticParams parse_haptic(const Node& node) {
  node.expect_keys({"reach_radius_m", "stiffness_Npm", "damping_Nspm", "static_friction", "dynamic_friction"});
  HapticParams haptic;
  if (node.has("reach_radius_m")) {
    haptic.reach_radius_m = node.child("reach_radius_m").positive_up_to(SceneLimits::kMaxReachRadius_m, " m");
  }
  if (node.has("stiffness_Npm")) {
    haptic.stiffness_Npm = node.child("stiffness_Npm").positive_up_to(limits::kMaxStiffness_Npm, " N/m");
  }
  if (node.has("damping_Nspm")) {
    haptic.damping_Nspm = node.child("damping_Nspm").in_range(0.0, limits::kMaxDamping_Nspm, " N·s/m");
  }
  if (node.has("static_friction") || node.has("dynamic_friction")) {
    if (!node.has("static_friction")) node.fail_missing("static_friction", "the finger material needs both");
    haptic.finger_material_given = true;
    haptic.finger_material = parse_material(node, haptic.finger_material);
  }
  return haptic;
}

// The keys every object may have; its shape's own come from the shape module.
constexpr std::string_view kObjectKeys[] = {
    "name", "shape", "dynamic", "mass_kg", "density_kgpm3", "position_m", "orientation_wxyz", "linear_velocity_mps",
    "angular_velocity_radps", "static_friction", "dynamic_friction", "restitution", "deformable"};

// The value named by string key `key` of `node` among two `choices`, or `fallback` when the key is absent; another
// string fails, naming the key and both choices.
template <class Enum>
Enum parse_choice(const Node& node, const char* key, const std::array<std::pair<const char*, Enum>, 2>& choices,
                  Enum fallback) {
  if (!node.has(key)) return fallback;
  const std::string name = node.child(key).string();
  for (const auto& [choice, value] : choices) {
    if (name == choice) return value;
  }
  node.child(key).fail(std::string("unknown ") + key + ", expected " + choices[0].first + " or " + choices[1].first);
}

// A "deformable" block (docs/scene-format.md): a plastic or elastic top face for a static box. The plastic ranges
// span the materials a finger can dent (wet clay at ~1 kPa to stiff wax at ~1 MPa) with room either side, the elastic
// ones foams to hard rubbers; grids a step can yield in milliseconds (DeformableSurface::kMaxCells) and elastic
// grids whose integration keeps up with real time (DeformableSurface::kMaxCellStepsPerSecond).
DeformableMaterial parse_deformable(const Node& node, const SceneObject& object) {
  node.expect_object();
  node.expect_keys({"law", "rule", "yield_stress_Pa", "flow_resistance_Paspm", "contact_radius_m", "cell_m",
                    "plasticity", "stiffness_Papm", "tension_Npm", "areal_density_kgpm2", "damping_Paspm"});
  if (object.dynamic) node.fail("only a static object can be deformable (\"dynamic\": false)");
  if (object.shape.kind != ShapeKind::box) node.fail("only a box can be deformable (its top face yields)");
  DeformableMaterial material;
  material.law = parse_choice(node, "law", {{{"plastic", DeformableMaterial::Law::plastic},
                                             {"elastic", DeformableMaterial::Law::elastic}}},
                              material.law);
  const bool elastic = material.law == DeformableMaterial::Law::elastic;
  for (const char* key : {"yield_stress_Pa", "flow_resistance_Paspm", "plasticity"}) {
    if (elastic && node.has(key)) node.child(key).fail("a key of the plastic law, and this slab's law is elastic");
  }
  for (const char* key : {"stiffness_Papm", "tension_Npm", "areal_density_kgpm2", "damping_Paspm"}) {
    if (!elastic && node.has(key)) {
      node.child(key).fail("a key of the elastic law, and this slab's law is plastic (add \"law\": \"elastic\")");
    }
  }
  if (node.has("stiffness_Papm")) {
    material.stiffness_Papm = node.child("stiffness_Papm").in_range(1e3, 1e10, " Pa/m");
  }
  if (node.has("tension_Npm")) material.tension_Npm = node.child("tension_Npm").in_range(0.0, 1e4, " N/m");
  if (node.has("areal_density_kgpm2")) {
    material.areal_density_kgpm2 = node.child("areal_density_kgpm2").in_range(1e-2, 1e4, " kg/m²");
  }
  if (node.has("damping_Paspm")) material.damping_Paspm = node.child("damping_Paspm").in_range(0.0, 1e9, " Pa·s/m");
  material.rule = parse_choice(node, "rule", {{{"impulse", DeformableMaterial::Rule::impulse},
                                               {"penetration", DeformableMaterial::Rule::penetration}}},
                               material.rule);
  if (node.has("yield_stress_Pa")) material.yield_stress_Pa = node.child("yield_stress_Pa").in_range(0.0, 1e8, " Pa");
  if (node.has("flow_resistance_Paspm")) {
    material.flow_resistance_Paspm = node.child("flow_resistance_Paspm").in_range(1e2, 1e12, " Pa·s/m");
  }
  if (node.has("contact_radius_m")) {
    material.contact_radius_m = node.child("contact_radius_m").in_range(1e-4, 0.1, " m");
  }
  if (node.has("cell_m")) material.cell_m = node.child("cell_m").in_range(1e-5, 0.05, " m");
  if (node.has("plasticity")) {
    material.plasticity = node.child("plasticity").in_range(0.0, 1.0, "");
    if (!(material.plasticity > 0.0)) node.child("plasticity").fail("must be above 0 (0 never dents)");
  }
  if (material.cell_m > 0.5 * material.contact_radius_m) {
    const Node at = node.has("cell_m") ? node.child("cell_m") : node;
    at.fail("cell_m must be at most half of contact_radius_m (" + readable(material.contact_radius_m) +
            " m), so the contact pad spans cells");
  }
  const Eigen::Vector3d half_m = 0.5 * Eigen::Vector3d(object.shape.box_size_m[0], object.shape.box_size_m[1],
                                                       object.shape.box_size_m[2]);
  if (DeformableSurface::cells_for(material, half_m) > DeformableSurface::kMaxCells) {
    const Node at = node.has("cell_m") ? node.child("cell_m") : node;
    at.fail("the top face would have more than " + std::to_string(DeformableSurface::kMaxCells) +
            " cells; use larger cells or a smaller box");
  }
  if (elastic) {
    const double cell_steps = DeformableSurface::cell_steps_per_second(material, half_m);
    if (cell_steps > DeformableSurface::kMaxCellStepsPerSecond) {
      node.fail("an elastic slab this stiff, light and fine (" + readable(cell_steps) +
                " cell updates per simulated second, above " + readable(DeformableSurface::kMaxCellStepsPerSecond) +
                ") would not keep up with real time; use larger cells, a smaller box, a softer skin or foundation, or "
                "a heavier layer");
    }
  }
  return material;
}

// A mesh's "surface": "facets" (its triangles, as they are; the default) or "smooth" (the surface they stand for, where
// it touches the floor: common/mesh/smooth_surface.h). Only a moving body's contacts use it, and only a mesh without
// edges is a smooth body's tessellation.
bool parse_smooth_surface(const Node& node, const SceneObject& object) {
  const std::string value = node.string();
  if (value == "facets") return false;
  if (value != "smooth") node.fail("must be \"facets\" or \"smooth\", not \"" + value + "\"");
  if (!object.dynamic) node.fail("only a dynamic mesh can be smooth (its contacts with the floor use the surface)");
  const auto* body = dynamic_cast<const MeshBody*>(find_mesh_geometry(object.shape.mesh_hash));
  if (body == nullptr) node.fail("its mesh was not loaded");
  const SmoothSurface& surface = body->smooth_surface();
  if (surface.largest_crease_rad() > SmoothSurface::kMaxCrease_rad) {
    constexpr double kDegrees = 180.0 / 3.14159265358979323846;
    node.fail("the mesh bends by " + readable(surface.largest_crease_rad() * kDegrees) + " degrees at an edge of " +
              "triangle " + std::to_string(surface.largest_crease_triangle()) + ", more than a smooth surface's " +
              readable(SmoothSurface::kMaxCrease_rad * kDegrees) + " from one triangle to the next: it has edges, " +
              "so leave it \"facets\"");
  }
  return true;
}

SceneObject parse_object(const Node& node, const std::string& scene_dir) {
  node.expect_object();
  SceneObject object;
  const ShapeKind kind = parse_shape_kind(node.required("shape"));
  node.expect_keys({std::span<const std::string_view>(kObjectKeys), shape_keys(kind)});
  object.name = node.required("name").string();
  if (object.name.empty()) node.child("name").fail("name must not be empty");
  object.dynamic = node.required("dynamic").boolean();
  // A mesh's triangles come from a file beside the scene (the shape module cannot read files).
  object.shape = kind == ShapeKind::mesh ? load_mesh_shape(node, scene_dir, object.dynamic) : parse_shape(node, kind);
  if (kind == ShapeKind::mesh && node.has("surface")) {
    object.smooth_surface = parse_smooth_surface(node.child("surface"), object);
  }

  if (object.dynamic) {
    const bool has_mass = node.has("mass_kg");
    const bool has_density = node.has("density_kgpm3");
    if (has_mass == has_density) {
      if (has_mass) node.child("density_kgpm3").fail("give either mass_kg or density_kgpm3, not both");
      node.fail_missing("mass_kg", "a dynamic object needs mass_kg or density_kgpm3");
    }
    constexpr double kMinMass = SceneLimits::kMinMass_kg;
    constexpr double kMaxMass = SceneLimits::kMaxMass_kg;
    object.mass_kg = has_mass ? node.child("mass_kg").in_range(kMinMass, kMaxMass, " kg")
                              : node.child("density_kgpm3").positive() * volume_m3(object.shape);
    if (!has_mass && !(object.mass_kg >= kMinMass && object.mass_kg <= kMaxMass)) {
      node.child("density_kgpm3").fail("density × volume = " + readable(object.mass_kg) + " kg; the mass must be " +
                                       "between " + readable(kMinMass) + " and " + readable(kMaxMass) + " kg");
    }
  } else {
    // A static object is immovable: a mass or a velocity would be silently ignored, so it is an error.
    for (std::string_view key : {"mass_kg", "density_kgpm3", "linear_velocity_mps", "angular_velocity_radps"}) {
      if (node.has(key)) node.child(key).fail("static objects cannot have " + std::string(key));
    }
  }

  {
    const Node position = node.required("position_m");
    object.position_m = position.numbers<3>();
    for (std::size_t i = 0; i < 3; ++i) {
      position.element(i).in_range(-SceneLimits::kMaxCoordinate_m, SceneLimits::kMaxCoordinate_m, " m");
    }
  }
  if (node.has("orientation_wxyz")) object.orientation_wxyz = node.child("orientation_wxyz").unit_quaternion();
  if (node.has("linear_velocity_mps")) {
    object.linear_velocity_mps = node.child("linear_velocity_mps").vector_up_to(SceneLimits::kMaxSpeed_mps, " m/s");
  }
  if (node.has("angular_velocity_radps")) {
    object.angular_velocity_radps =
        node.child("angular_velocity_radps").vector_up_to(SceneLimits::kMaxAngularSpeed_radps, " rad/s");
  }
  object.material = parse_material(node, Material{});
  if (node.has("deformable")) object.deformable = parse_deformable(node.child("deformable"), object);
  return object;
}


}  // namespace

namespace {

double stiffness_or_default(double stiffness_Npm) {
  return std::isnan(stiffness_Npm) ? PhysicsParams::kDefaultContactStiffness_Npm : stiffness_Npm;
}

double damping_or_default(double damping_Nspm) {
  return std::isnan(damping_Nspm) ? PhysicsParams::kDefaultContactDamping_Nspm : damping_Nspm;
}

}  // namespace

double PhysicsParams::erp_at(double substep_s) const {
  if (!contact_spring()) return ode.erp;
  const double hk = substep_s * stiffness_or_default(contact_stiffness_Npm);
  return hk / (hk + damping_or_default(contact_damping_Nspm));
}

double PhysicsParams::cfm_at(double substep_s) const {
  if (!contact_spring()) return ode.cfm;
  return 1.0 / (substep_s * stiffness_or_default(contact_stiffness_Npm) + damping_or_default(contact_damping_Nspm));
}

double combine_friction(double a, double b) { return std::sqrt(a * b); }
double combine_restitution(double a, double b) { return std::max(a, b); }

Scene parse_scene(const nlohmann::json& document, const std::string& source_name) {
  const Node root(document, "", source_name);
  root.expect_keys({"description", "gravity_mps2", "floor", "physics", "haptic", "tool", "objects"});
  if (root.has("description")) root.child("description").string();  // free text for the reader; must be a string

  Scene scene;
  scene.source_name = source_name;
  if (root.has("gravity_mps2")) {
    scene.gravity_mps2 = root.child("gravity_mps2").vector_up_to(SceneLimits::kMaxGravity_mps2, " m/s²");
  }
  if (root.has("floor")) scene.floor = parse_floor(root.child("floor"));
  if (root.has("physics")) scene.physics = parse_physics(root.child("physics"));
  if (root.has("haptic")) scene.haptic = parse_haptic(root.child("haptic"));
  if (root.has("tool")) {
    scene.tool = parse_tool_block(root.child("tool"), scene.gravity_mps2, scene_folder(source_name));
    // The world sends the planes of objects within the reach radius of the tool's grip: it must cover the tool, with
    // a finger's neighbourhood around its farthest point. Given, it is checked; not given, it is widened.
    const bool reach_given = root.has("haptic") && root.child("haptic").has("reach_radius_m");
    if (scene.tool->reach_m > SceneLimits::kMaxReachRadius_m - HapticParams{}.reach_radius_m) {
      root.child("tool").fail("the tool reaches " + readable(scene.tool->reach_m) + " m from its grip; the world's "
                              "reach radius, at most " + readable(SceneLimits::kMaxReachRadius_m) + " m, must cover "
                              "it with " + readable(HapticParams{}.reach_radius_m) + " m to spare");
    }
    if (!reach_given) {
      scene.haptic.reach_radius_m = HapticParams{}.reach_radius_m + scene.tool->reach_m;
    } else if (scene.haptic.reach_radius_m < scene.tool->reach_m) {
      root.child("haptic").child("reach_radius_m").fail(
          "must cover the tool, which reaches " + readable(scene.tool->reach_m) + " m from its grip (leave it out "
          "and the world widens it to the tool's reach plus " + readable(HapticParams{}.reach_radius_m) + " m)");
    }
  }

  const Node objects = root.required("objects");
  if (!objects.value().is_array()) objects.fail("expected an array of objects");
  if (objects.value().size() > SceneLimits::kMaxObjects) {
    objects.fail("a scene holds at most " + std::to_string(SceneLimits::kMaxObjects) + " objects, this one has " +
                 std::to_string(objects.value().size()));
  }
  // Mesh files are named relative to the scene file's folder (the working directory for a scene given as text).
  const std::string scene_dir = scene_folder(source_name);
  std::set<std::string> names;
  for (std::size_t i = 0; i < objects.value().size(); ++i) {
    const Node node = objects.element(i);
    SceneObject object = parse_object(node, scene_dir);
    if (!names.insert(object.name).second) node.child("name").fail("duplicate object name");
    scene.objects.push_back(std::move(object));
  }
  return scene;
}

Scene load_scene(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw SceneError(path + ": cannot open scene file");
  std::stringstream text;
  text << file.rdbuf();
  return parse_scene_text(text.str(), path);
}

namespace {

// Finds where JSON text first fails to parse, for errors nlohmann reports without a position (a number too large for
// a double, "1e999", throws out_of_range 406): a SAX pass that accepts everything and stops at the first error.
class ErrorLocator final : public nlohmann::json::json_sax_t {
 public:
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t bytes_read, const std::string& token, const nlohmann::detail::exception&) override {
    token_ = token;
    offset_ = bytes_read >= token.size() ? bytes_read - token.size() : 0;  // the parser has read past the token
    found_ = true;
    return false;
  }
  bool found() const { return found_; }
  const std::string& token() const { return token_; }
  std::size_t offset() const { return offset_; }

 private:
  bool found_ = false;
  std::string token_;
  std::size_t offset_ = 0;
};

// "line L, column C" of byte `offset` of `text` (both from 1).
std::string line_and_column(std::string_view text, std::size_t offset) {
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t k = 0; k < offset && k < text.size(); ++k) {
    if (text[k] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

}  // namespace

Scene parse_scene_text(std::string_view text, const std::string& source_name) {
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(text);
  } catch (const nlohmann::json::out_of_range& error) {
    // A number too large for a double ("1e999"): nlohmann gives no position, so find the offending token.
    ErrorLocator locator;
    nlohmann::json::sax_parse(text, &locator);
    const std::string where = locator.found() ? " at " + line_and_column(text, locator.offset()) : "";
    throw SceneError(source_name + ": not valid JSON" + where + ": number '" + locator.token().substr(0, 40) +
                     "' is out of range for a double");
  } catch (const nlohmann::json::exception& error) {
    throw SceneError(source_name + ": not valid JSON: " + excerpt(error.what()));  // nlohmann quotes the whole bad token
  }
  return parse_scene(document, source_name);
}

}  // namespace impetus
