// SPDX-License-Identifier: Apache-2.0
#pragma once
// One world view published through several transports at once (shared memory for viewers on the world's host, DDS
// for viewers elsewhere). Owns them.

#include "common/contract/world_view.h"

#include <memory>
#include <utility>
#include <memory>
#include <utility>
#include <vector>

namespace impetus {

class WorldViewTee final : public WorldViewPublisher {
 public:
  void add(std::unique_ptr<WorldViewPublisher> publisher) { publishers_.push_back(std::move(publisher)); }
  void publish_scene(const ViewScene& scene) override {
    for (const auto& publisher : publishers_) publisher->publish_scene(scene);
  }
  void publish_snapshot(const WorldSnapshot& snapshot) override {
    for (const auto& publisher : publishers_) publisher->publish_snapshot(snapshot);
  }

 private:
  std::vector<std::unique_ptr<WorldViewPublisher>> publishers_;
};

}  // namespace impetus
