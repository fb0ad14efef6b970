// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/shm_world_view.h"

#include "common/link/shm/names.h"

#include <cstring>

namespace impetus {

ShmWorldViewPublisher::ShmWorldViewPublisher(const std::string& shm)
    : segment_(Segment<WorldViewLayout>::create(world_view_name(shm))) {}

void ShmWorldViewPublisher::publish_scene(const ViewScene& scene) { segment_->scene.write(scene); }

void ShmWorldViewPublisher::publish_snapshot(const WorldSnapshot& snapshot) {
  segment_->snapshot.write(snapshot, snapshot.used_bytes());
}

ShmWorldViewReader::ShmWorldViewReader(const std::string& shm)
    : segment_(ReadOnlySegment<WorldViewLayout>::open(world_view_name(shm))) {}

bool ShmWorldViewReader::read_scene(ViewScene& out) {
  if (!segment_->scene.try_read(out, scene_sequence_)) return false;
  if (*scene_problem(out) != '\0') {
    ++rejected_;
    return false;
  }
  return true;
}

bool ShmWorldViewReader::read_snapshot(WorldSnapshot& out) {
  std::size_t copied = 0;
  if (!segment_->snapshot.try_read(out, snapshot_sequence_, 4, &copied)) return false;
  // The body count is part of what was copied; a count that needs more bodies than were written is a scribble.
  if (copied < offsetof(WorldSnapshot, bodies) || out.used_bytes() > copied || *snapshot_problem(out) != '\0') {
    ++rejected_;
    return false;
  }
  return true;
}

}  // namespace impetus
