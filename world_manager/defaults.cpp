// SPDX-License-Identifier: Apache-2.0
#include "world_manager/defaults.h"

#include "common/contract/frames.h"
#include "common/contract/limits.h"
#include "common/shape/shape.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"

namespace impetus {

nlohmann::json defaults_document() {
  // The scene parser's own answer for a scene that gives nothing, so these are its defaults by construction.
  const Scene scene = parse_scene(nlohmann::json{{"objects", nlohmann::json::array()}}, "defaults");
  nlohmann::json couplings = nlohmann::json::array();
  for (const Coupling coupling : {Coupling::impulse, Coupling::position, Coupling::local}) {
    couplings.push_back(to_string(coupling));
  }
  nlohmann::json shapes = nlohmann::json::array();
  for (std::uint32_t k = 1; k < kShapeKindCount; ++k) shapes.push_back(to_string(static_cast<ShapeKind>(k)));
  nlohmann::json engines = nlohmann::json::array();
  for (const EngineEntry& entry : engine_entries()) engines.push_back(std::string(entry.name));
  const PhysicsParams& physics = scene.physics;
  const HapticParams& haptic = scene.haptic;
  const ToolCoupling tool;
  return {
      {"couplings", couplings},
      {"engines", engines},
      {"shapes", shapes},
      {"haptic_rate_hz", limits::kDefaultHapticRate_Hz},
      {"scene",
       {{"gravity_mps2", scene.gravity_mps2},
        {"friction", Material::kDefaultFriction},
        {"restitution", Material{}.restitution},
        {"physics",
         {{"engine", physics.engine},
          {"world_rate_hz", physics.world_rate_hz},
          {"substeps", physics.substeps},
          {"speculative_contacts", physics.speculative_contacts},
          {"auto_disable", physics.auto_disable},
          {"seed", physics.seed}}},
        {"haptic",
         {{"reach_radius_m", haptic.reach_radius_m},
          {"stiffness_Npm", haptic.stiffness_Npm},
          {"damping_Nspm", haptic.damping_Nspm}}},
        {"tool",
         {{"mass_kg", ToolShape{}.mass_kg},
          {"stiffness_Npm", tool.stiffness_Npm},
          {"damping_Nspm", tool.damping_Nspm},
          {"rotational_stiffness_Nmprad", tool.rotational_stiffness_Nmprad},
          {"rotational_damping_Nmsprad", tool.rotational_damping_Nmsprad},
          {"max_force_N", tool.max_force_N},
          {"max_torque_Nm", tool.max_torque_Nm}}}}},
  };
}

}  // namespace impetus
