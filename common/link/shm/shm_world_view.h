// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world view over shared memory: the world manager publishes into "<shm>.view" (world_view_layout.h); viewers
// map it read-only, so a viewer that crashes, stalls or misbehaves cannot touch what the world or the haptic loop
// use. The writer never waits for a reader (seqlock.h).

#include "common/contract/world_view.h"
#include "common/link/shm/world_view_layout.h"

#include <cstdint>
#include <string>

namespace impetus {

class ShmWorldViewPublisher final : public WorldViewPublisher {
 public:
  // Creates "<shm>.view" (throws SegmentError if a live process owns it).
  explicit ShmWorldViewPublisher(const std::string& shm);

  void publish_scene(const ViewScene& scene) override;
  void publish_snapshot(const WorldSnapshot& snapshot) override;

 private:
  Segment<WorldViewLayout> segment_;
};

// A viewer's read-only end. Not thread-safe; one per viewer thread.
class ShmWorldViewReader final : public WorldViewReader {
 public:
  // Opens "<shm>.view" read-only; throws SegmentError (missing: the world has not started or has left).
  explicit ShmWorldViewReader(const std::string& shm);

  bool read_scene(ViewScene& out) override;
  bool read_snapshot(WorldSnapshot& out) override;
  // False once the world that created the segment has exited: open it again to follow a restarted world.
  bool world_alive() const override { return segment_.creator_alive(); }
  std::uint64_t rejected() const override { return rejected_; }
  const std::string& name() const override { return segment_.name(); }

 private:
  ReadOnlySegment<WorldViewLayout> segment_;
  std::uint64_t scene_sequence_ = 0;
  std::uint64_t snapshot_sequence_ = 0;
  std::uint64_t rejected_ = 0;
};

}  // namespace impetus
