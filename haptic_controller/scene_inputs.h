// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the haptic controller reads from the world's scene file (haptic_controller --meshes-from, --tool-from): the
// meshes' triangles, registered by their hash so the servo follows them between frames (common/mesh/mesh_object.h),
// and the tool in the hand (common/tool/tool_block.h), which the node then serves.

#include "haptic_controller/haptic_node.h"

#include <string>

namespace impetus {

// Reads `meshes_from`'s meshes (if given; and warns if that scene has a tool this controller will not render) and
// `tool_from`'s tool into `options` (if given). Throws InputError naming the file and field, std::invalid_argument
// for a --tool-from scene without a tool.
void read_scene_inputs(const std::string& meshes_from, const std::string& tool_from, HapticNodeOptions& options);

}  // namespace impetus
