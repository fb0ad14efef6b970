// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/engine_registry.h"

#include "common/runtime/message_text.h"
#include "world_manager/engine/bullet_engine.h"
#include "world_manager/engine/ode_engine.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/scene.h"

namespace impetus {
namespace {

std::unique_ptr<RigidBodyEngine> make_ode(const Scene& scene) { return std::make_unique<OdeEngine>(scene); }
std::unique_ptr<RigidBodyEngine> make_bullet(const Scene& scene) { return std::make_unique<BulletEngine>(scene); }

// The first is the default (PhysicsParams::engine).
constexpr EngineEntry kEngines[] = {
    {"ode", parse_ode_block, make_ode},
    {"bullet", parse_bullet_block, make_bullet},
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
  std::vector<std::string> names;
  for (const EngineEntry& entry : kEngines) names.emplace_back(entry.name);
  return one_of(names);
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
