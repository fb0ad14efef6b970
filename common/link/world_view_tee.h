// SPDX-License-Identifier: Apache-2.0
#pragma once
// One world view published through several transports at once (shared memory for viewers on the world's host, DDS
// for viewers elsewhere). Does not own them; each must outlive the tee.

#include "common/contract/world_view.h"

#include <vector>

namespace impetus {

class WorldViewTee final : public WorldViewPublisher {
 public:
  void add(WorldViewPublisher& publisher) { publishers_.push_back(&publisher); }
  void publish_scene(const ViewScene& scene) override {
    for (WorldViewPublisher* publisher : publishers_) publisher->publish_scene(scene);
  }
  void publish_snapshot(const WorldSnapshot& snapshot) override {
    for (WorldViewPublisher* publisher : publishers_) publisher->publish_snapshot(snapshot);
  }

 private:
  std::vector<WorldViewPublisher*> publishers_;
};

}  // namespace impetus
