// SPDX-License-Identifier: Apache-2.0
// ODE's block of a scene's physics: "physics": {"ode": {"solver", "solver_iterations", "erp", "cfm",
// "max_correcting_velocity_mps"}} (docs/scene-format.md).
#include "common/contract/limits.h"
#include "common/runtime/json_node.h"
#include "world_manager/engine/ode_engine.h"
#include "world_manager/scene.h"

namespace impetus {

void parse_ode_block(const JsonNode& block, PhysicsParams& physics) {
  block.expect_keys({"solver", "solver_iterations", "erp", "cfm", "max_correcting_velocity_mps"});
  OdeParams& ode = physics.ode;
  if (block.has("solver")) {
    const JsonNode solver = block.child("solver");
    const std::string name = solver.string();
    if (name == "quickstep") {
      ode.solver = OdeParams::Solver::quickstep;
    } else if (name == "direct") {
      ode.solver = OdeParams::Solver::direct;
    } else {
      solver.fail("expected \"quickstep\" or \"direct\"");
    }
  }
  if (block.has("solver_iterations")) {
    ode.solver_iterations = block.child("solver_iterations").positive_int(limits::kMaxSolverIterations);
  }
  // ODE's per-substep numbers as they are, or the contact as a spring and a damper: one model or the other.
  for (const char* key : {"erp", "cfm"}) {
    if (block.has(key) && physics.contact_spring()) {
      block.child(key).fail("give either \"erp\"/\"cfm\" (ODE's numbers per substep) or \"contact_stiffness_Npm\"/"
                            "\"contact_damping_Nspm\" (a spring and damper at any substep), not both");
    }
  }
  if (block.has("erp")) ode.erp = block.child("erp").in_unit_interval();
  if (block.has("cfm")) ode.cfm = block.child("cfm").in_range(0.0, SceneLimits::kMaxCfm, "");
  if (block.has("max_correcting_velocity_mps")) {
    ode.max_correcting_velocity_mps =
        block.child("max_correcting_velocity_mps").positive_up_to(SceneLimits::kMaxSpeed_mps, " m/s");
  }
}

}  // namespace impetus
