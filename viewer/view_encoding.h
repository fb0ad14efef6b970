// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer's messages to its page (view_protocol.h): the scene as JSON text, a snapshot as packed float64 values.

#include "common/contract/world_view.h"

#include <optional>
#include <string>

namespace impetus::view {

struct ReplayRange {
  double start_s = 0.0;
  double end_s = 0.0;
  std::size_t frame_count = 0;
};

// The scene message. `source`: the shared-memory name or the trial folder, shown on the page.
std::string scene_message(const ViewScene& scene, const std::string& source, const std::optional<ReplayRange>& replay);

// Replaces `out` with the frame message of `snapshot` (its used bodies and endpoints). Reuses `out`'s capacity.
void encode_frame(const WorldSnapshot& snapshot, bool playing, double speed, std::string& out);

}  // namespace impetus::view
