// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link inside one process (DESIGN.md §2 "In-process"): both ends in one object, frames handed over as they
// are, lockstep by construction. The haptic node is the master: step_world() runs the world node's step on the
// caller's thread, so a whole trial runs on one thread in a fixed order and is bitwise reproducible.

#include "common/link/world_link.h"

namespace impetus {

// What the in-process link calls for a world step (the world node implements it).
class WorldStepper {
 public:
  virtual ~WorldStepper() = default;
  virtual void step_world() = 0;
};

class InProcessWorldLink final : public WorldLinkServer, public WorldLinkClient {
 public:
  explicit InProcessWorldLink(const WorldLinkInfo& info) : info_(info) {}

  // The world node whose step_world() step_world(tick) runs; set before the first step.
  void connect(WorldStepper& world) { world_ = &world; }

  // World end.
  bool latest_report(HapticReport& out) override {
    if (have_report_) out = report_;
    return have_report_;
  }
  void publish_frame(const PlaneFrame& frame) override {
    frame_ = frame;
    frame_pending_ = true;
  }
  void publish_stats(const LoopStats& stats) override { stats_ = stats; }
  TurnResult wait_turn() override { return TurnResult::shutdown; }  // never waited on: step_world() drives the world
  void finish_turn() override {}
  std::uint64_t rejected_reports() const override { return 0; }

  // Haptic end.
  const WorldLinkInfo& info() const override { return info_; }
  bool receive_frame(PlaneFrame& out) override {
    if (!frame_pending_) return false;
    out = frame_;
    frame_pending_ = false;
    return true;
  }
  void publish_report(const HapticReport& report) override {
    report_ = report;
    have_report_ = true;
  }
  bool step_world(std::uint64_t) override {
    if (world_ == nullptr) return false;
    world_->step_world();
    return true;
  }
  void end_session() override {}
  bool reattach() override { return false; }
  std::uint64_t rejected_frames() const override { return 0; }
  std::uint64_t attaches() const override { return 1; }

  const LoopStats& world_stats() const { return stats_; }

 private:
  WorldLinkInfo info_;
  WorldStepper* world_ = nullptr;
  PlaneFrame frame_{};
  bool frame_pending_ = false;
  HapticReport report_{};
  bool have_report_ = false;
  LoopStats stats_{};
};

}  // namespace impetus
