// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world view (common/contract/world_view.h) over DDS, for viewers on other machines than the world's: the scene
// (reliable, transient local: a late viewer reads it at once) and a snapshot after every world step (best effort,
// keep last 1: a viewer shows the newest). Topics and types in impetus_link.idl. A viewer cannot disturb the world:
// it only reads, and a slow reader makes the world drop nothing but its own samples.

#include "common/contract/world_view.h"
#include "common/link/dds/dds_participant.h"

#include <memory>
#include <string>

namespace impetus {

class DdsWorldViewPublisher final : public WorldViewPublisher {
 public:
  explicit DdsWorldViewPublisher(const DdsLinkOptions& options);
  ~DdsWorldViewPublisher() override;

  void publish_scene(const ViewScene& scene) override;
  void publish_snapshot(const WorldSnapshot& snapshot) override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Follows whichever world publishes in the domain and partition: a restarted world's scene replaces the last one, so
// world_alive() stays true.
class DdsWorldViewReader final : public WorldViewReader {
 public:
  explicit DdsWorldViewReader(const DdsLinkOptions& options);
  ~DdsWorldViewReader() override;

  bool read_scene(ViewScene& out) override;
  bool read_snapshot(WorldSnapshot& out) override;
  bool world_alive() const override { return true; }
  std::uint64_t rejected() const override;
  const std::string& name() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace impetus
