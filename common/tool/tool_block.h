// SPDX-License-Identifier: Apache-2.0
#pragma once
// A scene's "tool" block (docs/scene-format.md "tool"): the tool's shape in the grip's frame, its mass, and the
// coupling, each value within its bound. Read by the world with the rest of its scene (world_manager/scene.h, which
// also checks the tool's reach against the world's) and by the haptic controller, which renders the tool
// (--tool-from SCENE): one reader, so the two cannot disagree about the tool.

#include "common/contract/limits.h"
#include "common/contract/tool.h"
#include "common/contract/vec3.h"
#include "common/runtime/json_node.h"

#include <optional>
#include <string>

namespace impetus {

struct ToolBlock {
  ToolShape shape;
  ToolCoupling coupling;
  double reach_m = 0.0;  // a bound on the tool's farthest point from the grip's centre
};

// A tool's bounds. A hand-held tool is at most an arm's length; its rotational coupling at most the linear bound at a
// 10 cm lever (k·r²), as the defaults (common/contract/tool.h); forces past 1 kN and torques past 100 N·m are no
// hand-held device's.
struct ToolLimits {
  static constexpr double kMaxToolReach_m = 1.0;
  static constexpr double kMaxRotationalStiffness_Nmprad = limits::kMaxStiffness_Npm * 0.01;
  static constexpr double kMaxRotationalDamping_Nmsprad = limits::kMaxDamping_Nspm * 0.01;
  static constexpr double kMaxToolForce_N = 1e3;
  static constexpr double kMaxToolTorque_Nm = 100.0;
  static constexpr double kMaxToolMass_kg = 10.0;  // a sledgehammer is 5 kg
};

// The block at `node`, its weight under `gravity_mps2`; a mesh's file is found from `scene_dir` (the scene file's
// folder: common/mesh/mesh_object.h). Throws InputError naming the file, the field and the value.
ToolBlock parse_tool_block(const JsonNode& node, const Vec3& gravity_mps2, const std::string& scene_dir);

// The tool of the scene file at `path` (its "tool" block under its "gravity_mps2"), or none if it has no tool block.
// Reads only those two keys; the world checks the rest. Throws InputError naming the file and field.
std::optional<ToolBlock> load_scene_tool(const std::string& path);

}  // namespace impetus
