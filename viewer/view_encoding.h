// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer's messages to its page (view_protocol.h): the scene as JSON text, a snapshot as packed float64 values.

#include "common/contract/tool.h"
#include "common/contract/world_view.h"

#include <optional>
#include <string>

namespace impetus::view {

struct ReplayRange {
  double start_s = 0.0;
  double end_s = 0.0;
  std::size_t frame_count = 0;
};

// A tool in the hand at one frame (a replay's, from the tool's pose log): world frame, SI.
struct ViewToolFrame {
  bool valid = false;  // false: no grip yet (before its first tick, or a tick without a pose)
  ViewBodyPose grip;   // the hand's grip
  ViewBodyPose proxy;  // where the tool is drawn: the proxy, held out of the objects
  Vec3 force_N{};      // on the grip
  Vec3 torque_Nm{};    // on the grip, about its centre
};

// The scene message. `source`: the shared-memory name or the trial folder, shown on the page. `tool`: the tool in the
// hand (its shape in the grip's frame), or nullptr.
std::string scene_message(const ViewScene& scene, const std::string& source, const std::optional<ReplayRange>& replay,
                          const ToolShape* tool = nullptr);

// Replaces `out` with the frame message of `snapshot` (its used bodies and endpoints) and, if `tool` is given, the
// tool's poses. Reuses `out`'s capacity.
void encode_frame(const WorldSnapshot& snapshot, bool playing, double speed, std::string& out,
                  const ViewToolFrame* tool = nullptr);

}  // namespace impetus::view
