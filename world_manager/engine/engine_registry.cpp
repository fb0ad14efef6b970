// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/engine_registry.h"

#include "world_manager/engine/ode_engine.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/scene.h"

namespace impetus {
namespace {

std::unique_ptr<RigidBodyEngine> make_ode(const Scene& scene) { return std::make_unique<OdeEngine>(scene); }

// The first is the default (PhysicsParams::engine).
constexpr EngineEntry kEngines[] = {
    {"ode", parse_ode_block, make_ode},
};

}  // namespace

std::span<const EngineEntry> engine_entries() { return kEngines; }

const EngineEntry* find_engine(std::string_view name) {
  for (const EngineEntry& entry : kEngines) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

std::string engine_names() {
  std::string names;
  const std::size_t count = std::size(kEngines);
  for (std::size_t k = 0; k < count; ++k) {
    if (k > 0) names += k + 1 == count ? " or " : ", ";
    names += kEngines[k].name;
  }
  return names;
}

std::unique_ptr<RigidBodyEngine> make_engine(const Scene& scene) {
  const EngineEntry* entry = find_engine(scene.physics.engine);
  if (entry == nullptr) {
    throw SceneError(scene.source_name + ": /physics/engine: unknown engine '" + scene.physics.engine +
                     "', expected " + engine_names());
  }
  return entry->make(scene);
}

void prepare_engines() { init_ode_once(); }

}  // namespace impetus
