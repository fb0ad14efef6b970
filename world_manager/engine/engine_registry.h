// SPDX-License-Identifier: Apache-2.0
#pragma once
// The rigid-body engines a scene can choose ("physics": {"engine": NAME}), in one table: each engine's name, the
// reader of its own block of the scene ("physics": {NAME: {...}}) and its factory. The scene parser and the World
// ask this table and nothing else, so adding an engine is its adapter (a RigidBodyEngine), its block's reader and a
// row here (docs/architecture.md §7).

#include "world_manager/engine/rigid_body_engine.h"

#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace impetus {

class JsonNode;
struct PhysicsParams;
struct Scene;

struct EngineEntry {
  std::string_view name;
  // Reads the engine's block into `physics` (after the engine-neutral keys, which it may check against); throws
  // SceneError naming the key and the value.
  void (*parse_block)(const JsonNode& block, PhysicsParams& physics);
  // Builds the engine for `scene` (which must outlive it). The process must have prepared the engine's library
  // (prepare_engines) first.
  std::unique_ptr<RigidBodyEngine> (*make)(const Scene& scene);
};

// Every entry, the default first.
std::span<const EngineEntry> engine_entries();
// The entry named `name`, or nullptr.
const EngineEntry* find_engine(std::string_view name);
// The names of every engine, as "a, b or c": for error messages.
std::string engine_names();
// The engine `scene.physics.engine` names; throws SceneError for a name the table does not hold.
std::unique_ptr<RigidBodyEngine> make_engine(const Scene& scene);
// Prepares every engine's library for this process (ODE's global initialisation); idempotent and thread-safe. Each
// program calls it once before building a World.
void prepare_engines();

}  // namespace impetus
