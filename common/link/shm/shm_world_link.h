// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link over shared memory (docs/architecture.md §2): one segment "<shm>.world" (world_link_layout.h), created
// by the world node, opened by the haptic node. Frames cross as sealed wire frames (wire_frames.h); lockstep turns are
// the segment's turns (futex words); liveness is the creator's pid and start time.

#include "common/link/shm/latest_valid.h"
#include "common/link/shm/world_link_layout.h"
#include "common/link/world_link.h"

#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace impetus {

class ShmWorldLinkServer final : public WorldLinkServer {
 public:
  // Creates "<shm>.world" with `info` (throws SegmentError if a live process owns it).
  ShmWorldLinkServer(const std::string& shm, const WorldLinkInfo& info);

  std::uint32_t endpoint_slots() const override { return kMaxEndpoints; }
  bool latest_report(std::uint32_t slot, HapticReport& out) override;
  void publish_frame(std::uint32_t slot, const PlaneFrame& frame) override;
  void publish_stats(const LoopStats& stats) override;
  bool latest_haptic_stats(std::uint32_t slot, LoopStats& out) override;
  TurnResult wait_turn() override;
  void finish_turn() override;
  std::uint64_t rejected_reports() const override;
  std::uint64_t channel_repairs() const override { return repairs_; }

  const std::string& name() const { return segment_.name(); }

 private:
  struct SlotReader {
    LatestValid<wire::HapticReport, HapticReport> reports;
    std::uint64_t stats_sequence = 0;
    LoopStats stats{};
  };

  Segment<WorldLinkLayout> segment_;
  wire::PlaneFrame frame_wire_{};
  std::vector<SlotReader> slots_;  // kMaxEndpoints (~14 KB each: on the heap)
  std::uint64_t repairs_ = 0;
};

class ShmWorldLinkClient final : public WorldLinkClient {
 public:
  // Opens "<shm>.world", waiting up to `wait_s` for the world node to create it, and takes an endpoint slot for each
  // of `endpoints` endpoints. In lockstep the first controller becomes the master and later ones its followers.
  // Throws SegmentError if the world does not appear in time, std::runtime_error if the world runs another clock
  // than `clock` or has too few free slots.
  ShmWorldLinkClient(const std::string& shm, ClockMode clock, double wait_s, std::uint32_t endpoints = 1);
  // Gives the slots back.
  ~ShmWorldLinkClient() override;

  const WorldLinkInfo& info() const override { return info_; }
  std::uint32_t endpoints() const override { return endpoints_; }
  bool receive_frame(EndpointId endpoint, PlaneFrame& out) override;
  void publish_report(const HapticReport& report) override;
  void publish_stats(const LoopStats& stats) override;
  bool step_world(std::uint64_t tick) override;
  void end_session() override;
  bool world_alive() const override;
  bool reattach() override;
  std::uint64_t rejected_frames() const override { return rejected_; }
  std::uint64_t attaches() const override { return attaches_.load(); }
  std::uint64_t channel_repairs() const override { return repairs_; }
  bool follower() const override { return current().follower; }
  bool wait_for_followers(std::uint32_t count) override;
  void lead_followers(std::uint64_t tick) override;
  TurnResult wait_follower_turn(std::uint64_t& tick) override;
  void finish_follower_turn() override;

  const std::string& name() const { return name_; }
  // The slot endpoint `endpoint` holds in the current world's segment (tests).
  std::uint32_t slot_of(EndpointId endpoint) const { return current().slots[endpoint]; }

 private:
  // One world segment attached to and the slots taken in it.
  struct Attachment {
    std::unique_ptr<Segment<WorldLinkLayout>> segment;
    std::array<std::uint32_t, kMaxEndpoints> slots{};
    bool follower = false;  // lockstep: another controller is the master; the turns come in slots[0]
  };
  // Takes the slots (and, lockstep, the master's place) in `segment`; throws std::runtime_error if it cannot.
  std::unique_ptr<Attachment> attach(std::unique_ptr<Segment<WorldLinkLayout>> segment) const;
  const Attachment& current() const { return *current_.load(std::memory_order_acquire); }
  WorldLinkLayout& world() const { return **current().segment; }

  std::uint64_t repairs_ = 0;
  std::string name_;
  ClockMode clock_;
  std::uint32_t endpoints_;
  WorldLinkInfo info_;
  // Every world attached to, oldest first: a restarted world creates a new segment, and the old mapping stays (never
  // unmapped while the servo thread may still read it) while `current_` moves on.
  std::vector<std::unique_ptr<Attachment>> worlds_;
  std::atomic<const Attachment*> current_{nullptr};
  const Attachment* frames_from_ = nullptr;
  std::array<std::uint64_t, kMaxEndpoints> last_frame_sequence_{};
  bool world_alive_ = true;  // lockstep: false once the world left mid-session
  wire::PlaneFrame frame_wire_{};
  wire::HapticReport report_wire_{};
  std::uint64_t rejected_ = 0;
  std::atomic<std::uint64_t> attaches_{1};
};

}  // namespace impetus
