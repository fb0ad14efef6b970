// SPDX-License-Identifier: Apache-2.0
#pragma once
// The scene model (docs/architecture.md §4; the format: docs/scene-format.md): what a world contains, parsed and
// validated from JSON before anything starts.
//
// Every key with its unit, range and default is in docs/scene-format.md; a shape's own keys are its kind's
// (common/shape/shape.h shape_keys). Unknown keys (a box's "radius_m") are errors, and every error throws SceneError
// with the message `FILE: /json/pointer: reason (got VALUE)`. Every number must lie in a range the engine can simulate:
// SceneLimits below and common/contract/limits.h, each bound with its reason next to it.

#include "common/contract/limits.h"
#include "common/contract/tool.h"
#include "common/tool/tool_block.h"
#include "common/contract/vec3.h"
#include "common/runtime/input_error.h"
#include "common/shape/shape.h"
#include "world_manager/deform/deformable_material.h"

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace impetus {

// A bad scene: the message names the file, the JSON path and the value.
using SceneError = InputError;

// The physical ranges a scene's values must lie in. ODE's broadphase stores bounding boxes as integers in cells of
// 1/8 m and asserts when a coordinate leaves that range (measured: 10^6 m works, 10^12 m aborts), and its solver
// loses all digits when masses or lengths differ by more than ~10^12; these ranges keep a scene well inside both.
struct SceneLimits {
  static constexpr double kMinLength_m = limits::kMinLength_m;  // sizes and radii (common/contract/limits.h)
  static constexpr double kMaxLength_m = limits::kMaxLength_m;
  static constexpr double kMaxCoordinate_m = 1e4;  // positions and floor height: a 20 km world around the device
  static constexpr double kMinMass_kg = 1e-6;      // 1 mg
  static constexpr double kMaxMass_kg = 1e6;       // 1000 t
  static constexpr double kMaxSpeed_mps = 1e3;     // faster than a rifle bullet
  static constexpr double kMaxAngularSpeed_radps = 1e4;  // ~1600 turns per second
  static constexpr double kMaxGravity_mps2 = limits::kMaxGravity_mps2;
  static constexpr double kMaxFriction = 100.0;    // real pairs stay below ~2; 100 already holds like glue
  static constexpr double kMaxCfm = 1.0;           // ODE: CFM above 1 makes every contact softer than the body it holds
  // Bounds against typing errors, each 10^4–10^6 times off the default contact's (PhysicsParams); at the lowest
  // stiffness a 1 g body rests 1 cm deep: no contact at all.
  static constexpr double kMinContactStiffness_Npm = 1.0;
  static constexpr double kMaxContactStiffness_Npm = 1e12;
  static constexpr double kMaxContactDamping_Nspm = 1e9;
  static constexpr double kMaxReachRadius_m = 10.0;  // 30× a desktop device's workspace (a tool's: tool_block.h)
  // A world step costs O(objects) in ODE's broadphase and our feature grid; 10^4 static spheres step in ~35 ms on
  // this class of machine (within a 20 Hz period) and 10^5 in tens of seconds (docs/reliability.md).
  static constexpr std::size_t kMaxObjects = 10'000;
};
// A body the solver throws beyond this distance from the origin is taken out of the simulation (World reports it):
// 100× the largest scene coordinate, 10^6 below where ODE's broadphase aborts.
inline constexpr double kEscapeDistance_m = 1e6;

// A surface material. Coefficients are dimensionless; dynamic_friction <= static_friction; restitution in [0, 1].
struct Material {
  // Dry wood or plastic on a table: a common default that neither slips nor sticks unrealistically.
  static constexpr double kDefaultFriction = 0.5;
  double static_friction = kDefaultFriction;
  double dynamic_friction = kDefaultFriction;
  double restitution = 0.0;  // default: contacts do not bounce
};

// Contact between two materials. Geometric mean for friction (a slippery surface makes the pair slippery, and
// mu with itself gives mu); the larger restitution (a bouncy ball bounces on any floor).
double combine_friction(double a, double b);
double combine_restitution(double a, double b);

struct SceneObject {
  std::string name;
  Shape shape;  // common/shape/shape.h
  bool dynamic = false;
  double mass_kg = 0.0;  // dynamic: resolved from mass_kg or density × volume; static: 0 (immovable)
  Vec3 position_m{};
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};  // unit quaternion, body → world
  Vec3 linear_velocity_mps{};
  Vec3 angular_velocity_radps{};  // world frame
  Material material;
  // A dynamic mesh that touches the floor with the smooth surface its triangles stand for ("surface": "smooth"):
  // common/mesh/smooth_surface.h.
  bool smooth_surface = false;
  // A static box whose top face yields where it is pressed (world_manager/deform/deformable_surface.h); the scene's
  // "deformable" block.
  std::optional<DeformableMaterial> deformable;
};

struct Floor {
  bool present = true;
  double height_m = 0.0;  // the plane z = height_m; solid below
  Material material;
};

struct HapticParams {
  // A fingertip-sized neighbourhood (paper §3.1): planes of objects farther than this plus what can move in one world
  // period are not needed before the next frame.
  double reach_radius_m = 0.05;
  double stiffness_Npm = 2000.0;  // paper §4.2.1
  // About 5 N·s/m damps the 2 kN/m spring on a ~0.1 kg fingertip near critically (2·sqrt(k·m) ≈ 28 N·s/m is
  // critical; the hand adds its own damping), and keeps k_d/Δt well inside the 1 kHz stability bound.
  double damping_Nspm = 5.0;
  bool finger_material_given = false;  // false: planes carry the object's own friction
  Material finger_material;
};

// ODE's own settings: the scene's "physics": {"ode": {...}} (world_manager/engine/ode_params.cpp reads them).
struct OdeParams {
  // QuickStep is ODE's fast iterative solver; it converges badly when a light body carries a much heavier one
  // (a 1000:1 stack collapses at any iteration count), where the direct solver is exact but cubic in the contacts.
  enum class Solver { quickstep, direct };
  Solver solver = Solver::quickstep;
  int solver_iterations = 20;  // ODE's own default for QuickStep; enough for stacks of a few boxes
  // ODE's error reduction and constraint force mixing, used as they are at every substep (ODE's own semantics): a
  // contact then acts as a spring k = ERP/(h·CFM) and a damper c = (1 − ERP)/CFM, so it stiffens as the substep h
  // shortens. ERP 0.2 is ODE's default; a CFM of 1e-5 (ODE's is 1e-10 in double) lets QuickStep settle stacks
  // without jitter. Not with the engine-neutral contact spring (PhysicsParams::contact_stiffness_Npm).
  double erp = 0.2;
  double cfm = 1e-5;
  // ERP removes a fraction of each contact's penetration per substep, as a separating speed erp·depth/h; this caps
  // that speed. An impact that penetrates (speculative contacts off) turns the correction into a bounce nobody asked
  // for, which a low cap suppresses; the cap also slows the removal of any penetration (2 mm takes 0.4 s at
  // 5 mm/s), so it is off unless a scene asks for it. Infinity: no cap (ODE's default).
  double max_correcting_velocity_mps = std::numeric_limits<double>::infinity();
};

// Bullet's own settings: the scene's "physics": {"bullet": {...}} (world_manager/engine/bullet_params.cpp).
struct BulletParams {
  // Sequential impulses are Bullet's iterative solver, with QuickStep's weakness (a light body under a heavy one);
  // direct is its MLCP solver with the Dantzig pivoting method, which solves each island's contact LCP exactly (cubic
  // in the contact rows) and falls back to sequential impulses for a substep it cannot solve (counted by Bullet).
  enum class Solver { sequential_impulse, direct };
  Solver solver = Solver::sequential_impulse;
  // Sequential-impulse sweeps per substep: ODE's QuickStep count, so the two iterate alike (Bullet's default is 10).
  int solver_iterations = 20;
};

// How the world is simulated: engine-neutral settings, and each engine's own block (docs/scene-format.md "physics").
struct PhysicsParams {
  // The rigid-body engine, by its name in the registry (world_manager/engine/engine_registry.h).
  std::string engine = "ode";
  double world_rate_hz = 20.0;  // paper §4.2.1
  // 50 ms is too coarse for contacts: a body falls g·T² ≈ 2.5 cm into the floor in one step, half a 5 cm cube.
  // Ten 5 ms substeps keep that under 0.25 mm for the cost of ten cheap steps.
  int substeps = 10;
  // Every contact as a spring and a damper that stay the same at any world rate and substep count. ODE is given them
  // per substep as ERP = h·k / (h·k + c), CFM = 1 / (h·k + c) (ODE manual, "Joint error and the ERP" and "Soft
  // constraint and CFM"). NaN: not given (then the engine's own contact, e.g. ODE's ERP and CFM). A scene that gives
  // one of the two gets the other from kDefaultContact*: ODE's ERP 0.2 and CFM 1e-5 at 5 ms substeps (20 Hz × 10),
  // where the two models agree exactly. A 1 kg body rests m·g/k = 2.5 µm deep on one such contact (a box on four,
  // 0.6 µm); a contact's correction time constant c/k is 20 ms.
  static constexpr double kDefaultContactStiffness_Npm = 4e6;  // 0.2 / (0.005 s · 1e-5)
  static constexpr double kDefaultContactDamping_Nspm = 8e4;   // 0.8 / 1e-5
  double contact_stiffness_Npm = std::numeric_limits<double>::quiet_NaN();
  double contact_damping_Nspm = std::numeric_limits<double>::quiet_NaN();
  bool contact_spring() const { return !std::isnan(contact_stiffness_Npm) || !std::isnan(contact_damping_Nspm); }
  // Contacts made one substep before a pair meets, which let it close the gap and no more
  // (engine/speculative_contacts.h): an impact then neither sinks v·h into the other body nor gets the solver's
  // push-out back as a bounce. Off: contacts only once bodies overlap.
  bool speculative_contacts = true;
  // A body resting for half a second leaves the simulation until something pushes or touches it
  // (engine/sleeping_bodies.h): "model only what a scene needs". The tap trial's cube ends within 60 nm of where it ends
  // with it off (docs/sleeping.md); off keeps every body simulated.
  bool auto_disable = true;
  std::uint64_t seed = 1;  // the engine's random stream, so runs are bitwise reproducible
  OdeParams ode;
  BulletParams bullet;

  // What ODE is given for substeps of `substep_s`: its ERP and CFM as they are, or from the spring and damper.
  double erp_at(double substep_s) const;
  double cfm_at(double substep_s) const;
  double world_period_s() const { return 1.0 / world_rate_hz; }
};

// A tool in the hand (the scene's "tool" block; docs/tool.md): a rigid tool held by the first endpoint. The world
// does not simulate it; the haptic side's tool servo renders it against the objects (haptic_controller/tool/).
using SceneTool = ToolBlock;

struct Scene {
  std::string source_name;  // file the scene came from, for messages
  Vec3 gravity_mps2{0.0, 0.0, -limits::kStandardGravity_mps2};
  Floor floor;
  std::vector<SceneObject> objects;  // an object's index is its object_id on the world link
  HapticParams haptic;
  PhysicsParams physics;
  std::optional<SceneTool> tool;  // none: the endpoints are points (fingers)

  // object_id of the floor on the world link: one past the objects.
  std::int32_t floor_object_id() const { return static_cast<std::int32_t>(objects.size()); }
};

// Reads and validates a scene file; throws SceneError (also for unreadable files and JSON syntax errors).
Scene load_scene(const std::string& path);
// Validates an already-parsed document; `source_name` prefixes every error message.
Scene parse_scene(const nlohmann::json& document, const std::string& source_name);
// Parses and validates scene text (the body of load_scene without the file); throws SceneError, also for bad JSON.
Scene parse_scene_text(std::string_view text, const std::string& source_name);

}  // namespace impetus
