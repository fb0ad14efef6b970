// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link over shared memory (DESIGN.md §2): one segment "<shm>.world" (world_link_layout.h), created by the
// world node, opened by the haptic node. Frames cross as sealed wire frames (wire_frames.h); lockstep turns are the
// segment's turns (futex words); liveness is the creator's pid and start time.

#include "common/link/shm/latest_valid.h"
#include "common/link/shm/world_link_layout.h"
#include "common/link/world_link.h"

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace impetus {

class ShmWorldLinkServer final : public WorldLinkServer {
 public:
  // Creates "<shm>.world" with `info` (throws SegmentError if a live process owns it).
  ShmWorldLinkServer(const std::string& shm, const WorldLinkInfo& info);

  bool latest_report(HapticReport& out) override;
  void publish_frame(const PlaneFrame& frame) override;
  void publish_stats(const LoopStats& stats) override;
  bool latest_haptic_stats(LoopStats& out) override;
  TurnResult wait_turn() override;
  void finish_turn() override;
  std::uint64_t rejected_reports() const override { return reports_.rejected(); }
  std::uint64_t channel_repairs() const override { return repairs_; }

  const std::string& name() const { return segment_.name(); }

 private:
  Segment<WorldLinkLayout> segment_;
  wire::PlaneFrame frame_wire_{};
  LatestValid<wire::HapticReport, HapticReport> reports_;
  std::uint64_t repairs_ = 0;
  std::uint64_t haptic_stats_sequence_ = 0;
  LoopStats haptic_stats_{};
};

class ShmWorldLinkClient final : public WorldLinkClient {
 public:
  // Opens "<shm>.world", waiting up to `wait_s` for the world node to create it; throws SegmentError after that, or
  // std::runtime_error if the world runs another clock than `clock`.
  ShmWorldLinkClient(const std::string& shm, ClockMode clock, double wait_s);

  const WorldLinkInfo& info() const override { return info_; }
  bool receive_frame(PlaneFrame& out) override;
  void publish_report(const HapticReport& report) override;
  void publish_stats(const LoopStats& stats) override;
  bool step_world(std::uint64_t tick) override;
  void end_session() override;
  bool world_alive() const override;
  bool reattach() override;
  std::uint64_t rejected_frames() const override { return rejected_; }
  std::uint64_t attaches() const override { return attaches_.load(); }
  std::uint64_t channel_repairs() const override { return repairs_; }

  const std::string& name() const { return name_; }

 private:
  WorldLinkLayout& world() const { return *current_.load(std::memory_order_acquire); }

  std::uint64_t repairs_ = 0;
  std::string name_;
  ClockMode clock_;
  WorldLinkInfo info_;
  // Every world segment attached to, oldest first: a restarted world creates a new one, and the old mapping stays
  // (never unmapped while the servo thread may still read it) while `current_` moves on.
  std::vector<std::unique_ptr<Segment<WorldLinkLayout>>> worlds_;
  std::atomic<WorldLinkLayout*> current_{nullptr};
  WorldLinkLayout* frames_from_ = nullptr;
  std::uint64_t last_frame_sequence_ = 0;
  bool world_alive_ = true;  // lockstep: false once the world left mid-session
  wire::PlaneFrame frame_wire_{};
  wire::HapticReport report_wire_{};
  std::uint64_t rejected_ = 0;
  std::atomic<std::uint64_t> attaches_{1};
};

}  // namespace impetus
