// SPDX-License-Identifier: Apache-2.0
// Bullet's block of a scene's physics: "physics": {"bullet": {"solver", "solver_iterations"}} (docs/scene-format.md).
#include "common/contract/limits.h"
#include "common/runtime/json_node.h"
#include "world_manager/engine/bullet_engine.h"
#include "world_manager/scene.h"

namespace impetus {

void parse_bullet_block(const JsonNode& block, PhysicsParams& physics) {
  block.expect_keys({"solver", "solver_iterations"});
  if (block.has("solver")) {
    const JsonNode solver = block.child("solver");
    const std::string name = solver.string();
    if (name == "sequential_impulse") {
      physics.bullet.solver = BulletParams::Solver::sequential_impulse;
    } else if (name == "direct") {
      physics.bullet.solver = BulletParams::Solver::direct;
    } else {
      solver.fail("expected \"sequential_impulse\" or \"direct\"");
    }
  }
  if (block.has("solver_iterations")) {
    physics.bullet.solver_iterations = block.child("solver_iterations").positive_int(limits::kMaxSolverIterations);
  }
}

}  // namespace impetus
