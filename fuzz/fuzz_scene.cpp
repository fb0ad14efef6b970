// SPDX-License-Identifier: Apache-2.0
// Fuzz target: scene files. Bytes → parse_scene_text (nlohmann::json::parse, then parse_scene), exactly what
// load_scene does after reading the file. Expected outcomes: a Scene or a SceneError (bad JSON included). Any other
// exception escapes and terminates: it is a bug, since a daemon's main would report it as an unknown error instead of
// pointing at the field. An accepted scene must hold only numbers the world manager can use.

#include "world_manager/scene.h"
#include "common/contract/limits.h"
#include "fuzz/fuzz_check.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <cstdint>
#include <string_view>

namespace {

bool finite3(const impetus::Vec3& v) { return impetus::all_finite(v); }

bool material_ok(const impetus::Material& m) {
  return std::isfinite(m.static_friction) && std::isfinite(m.dynamic_friction) && std::isfinite(m.restitution) &&
         m.dynamic_friction >= 0.0 && m.dynamic_friction <= m.static_friction && m.restitution >= 0.0 &&
         m.restitution <= 1.0;
}

// The same length the parser checks (std::hypot), so a value on the bound is judged alike.
double hypot3(const impetus::Vec3& v) { return std::hypot(v[0], v[1], v[2]); }

bool within(double x, double lowest, double highest) { return x >= lowest && x <= highest; }

bool coordinates_ok(const impetus::Vec3& v) {
  using impetus::SceneLimits;
  for (double x : v) {
    if (!within(x, -SceneLimits::kMaxCoordinate_m, SceneLimits::kMaxCoordinate_m)) return false;
  }
  return true;
}

// The physical ranges of scene.h (SceneLimits): what keeps ODE's broadphase and solver away from their asserts.
void check_limits(const impetus::Scene& scene) {
  using impetus::SceneLimits;
  FUZZ_CHECK(scene.objects.size() <= SceneLimits::kMaxObjects);
  FUZZ_CHECK(hypot3(scene.gravity_mps2) <= SceneLimits::kMaxGravity_mps2);
  FUZZ_CHECK(within(scene.floor.height_m, -SceneLimits::kMaxCoordinate_m, SceneLimits::kMaxCoordinate_m));
  FUZZ_CHECK(
      within(scene.physics.world_rate_hz, impetus::limits::kMinWorldRate_Hz, impetus::limits::kMaxWorldRate_Hz));
  FUZZ_CHECK(scene.physics.substeps <= impetus::limits::kMaxSubsteps);
  FUZZ_CHECK(scene.physics.ode.solver_iterations <= impetus::limits::kMaxSolverIterations);
  for (const impetus::SceneObject& object : scene.objects) {
    FUZZ_CHECK(coordinates_ok(object.position_m));
    FUZZ_CHECK(hypot3(object.linear_velocity_mps) <= SceneLimits::kMaxSpeed_mps);
    FUZZ_CHECK(hypot3(object.angular_velocity_radps) <= SceneLimits::kMaxAngularSpeed_radps);
    if (object.dynamic) FUZZ_CHECK(within(object.mass_kg, SceneLimits::kMinMass_kg, SceneLimits::kMaxMass_kg));
    const impetus::Shape& shape = object.shape;
    if (shape.kind == impetus::ShapeKind::box) {
      for (double size : shape.box_size_m) {
        FUZZ_CHECK(within(size, SceneLimits::kMinLength_m, SceneLimits::kMaxLength_m));
      }
    } else {
      FUZZ_CHECK(within(shape.radius_m, SceneLimits::kMinLength_m, SceneLimits::kMaxLength_m));
      FUZZ_CHECK(within(shape.length_m, 0.0, SceneLimits::kMaxLength_m));
    }
  }
}

// What scene.h promises about a scene that parsed.
void check_scene(const impetus::Scene& scene) {
  check_limits(scene);
  FUZZ_CHECK(finite3(scene.gravity_mps2));
  FUZZ_CHECK(std::isfinite(scene.floor.height_m));
  FUZZ_CHECK(material_ok(scene.floor.material));
  const impetus::PhysicsParams& physics = scene.physics;
  FUZZ_CHECK(physics.world_rate_hz > 0.0 && std::isfinite(physics.world_rate_hz));
  FUZZ_CHECK(std::isfinite(physics.world_period_s()));
  FUZZ_CHECK(physics.substeps > 0 && physics.ode.solver_iterations > 0);
  // ODE's ERP in [0, 1] and a finite CFM >= 0 at any substep a world can take.
  for (const double substep_s : {physics.world_period_s() / physics.substeps, 1e-7, 1.0}) {
    const double erp = physics.erp_at(substep_s), cfm = physics.cfm_at(substep_s);
    FUZZ_CHECK(erp >= 0.0 && erp <= 1.0);
    FUZZ_CHECK(cfm >= 0.0 && std::isfinite(cfm));
  }
  const impetus::HapticParams& haptic = scene.haptic;
  FUZZ_CHECK(haptic.reach_radius_m > 0.0 && std::isfinite(haptic.reach_radius_m));
  FUZZ_CHECK(haptic.stiffness_Npm > 0.0 && std::isfinite(haptic.stiffness_Npm));
  FUZZ_CHECK(haptic.damping_Nspm >= 0.0 && std::isfinite(haptic.damping_Nspm));
  FUZZ_CHECK(material_ok(haptic.finger_material));
  if (scene.tool) {
    // What the tool servo's constructor requires (tool_proxy.h), and a world reach that covers the tool.
    const impetus::ToolCoupling& c = scene.tool->coupling;
    FUZZ_CHECK(c.stiffness_Npm > 0.0 && std::isfinite(c.stiffness_Npm));
    FUZZ_CHECK(c.rotational_stiffness_Nmprad > 0.0 && std::isfinite(c.rotational_stiffness_Nmprad));
    FUZZ_CHECK(c.damping_Nspm >= 0.0 && c.rotational_damping_Nmsprad >= 0.0);
    FUZZ_CHECK(c.max_force_N > 0.0 && c.max_torque_Nm > 0.0);
    FUZZ_CHECK(scene.tool->shape.shape.kind != impetus::ShapeKind::mesh);
    FUZZ_CHECK(scene.tool->shape.placement.position_m.allFinite());
    // A weight the device can hold (scene.cpp parse_tool).
    FUZZ_CHECK(scene.tool->shape.mass_kg >= 0.0 && scene.tool->shape.weight_N.allFinite());
    FUZZ_CHECK(scene.tool->shape.weight_N.norm() <= c.max_force_N);
    FUZZ_CHECK(std::isfinite(scene.tool->reach_m) && scene.tool->reach_m > 0.0);
    FUZZ_CHECK(haptic.reach_radius_m >= scene.tool->reach_m);
    FUZZ_CHECK(haptic.reach_radius_m <= impetus::SceneLimits::kMaxReachRadius_m);
  }
  for (const impetus::SceneObject& object : scene.objects) {
    FUZZ_CHECK(!object.name.empty());
    FUZZ_CHECK(finite3(object.position_m) && finite3(object.linear_velocity_mps) &&
               finite3(object.angular_velocity_radps));
    for (double q : object.orientation_wxyz) FUZZ_CHECK(std::isfinite(q));
    FUZZ_CHECK(material_ok(object.material));
    const impetus::Shape& shape = object.shape;
    FUZZ_CHECK(finite3(shape.box_size_m) && std::isfinite(shape.radius_m) && std::isfinite(shape.length_m));
    // A dynamic body's mass goes to ODE's dMassAdjust: zero, infinite or NaN breaks the whole world step.
    if (object.dynamic) FUZZ_CHECK(object.mass_kg > 0.0 && std::isfinite(object.mass_kg));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    check_scene(impetus::parse_scene_text(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json"));
  } catch (const impetus::SceneError& error) {
    // A message quotes at most a short excerpt of the input, however large the input (fuzz/regressions/*.gen).
    FUZZ_CHECK(std::strlen(error.what()) < impetus::fuzz::kMaxMessageChars);
  }
  return 0;
}
