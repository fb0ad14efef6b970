// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/scene_inputs.h"

#include "common/mesh/mesh_object.h"
#include "common/tool/tool_block.h"

#include <cstdio>
#include <optional>
#include <stdexcept>

namespace impetus {

void read_scene_inputs(const std::string& meshes_from, const std::string& tool_from, HapticNodeOptions& options) {
  if (!meshes_from.empty()) {
    load_scene_meshes(meshes_from);
    if (tool_from.empty() && load_scene_tool(meshes_from)) {
      std::fprintf(stderr, "haptic_controller: warning: %s has a tool (its \"tool\" block), and this controller "
                   "renders point fingers: --device grip --tool-from SCENE renders the tool\n", meshes_from.c_str());
    }
  }
  if (tool_from.empty()) return;
  const std::optional<ToolBlock> tool = load_scene_tool(tool_from);
  if (!tool) throw std::invalid_argument("--tool-from " + tool_from + ": the scene has no \"tool\" block");
  options.tool = tool->shape;
  options.tool_coupling = tool->coupling;
}

}  // namespace impetus
