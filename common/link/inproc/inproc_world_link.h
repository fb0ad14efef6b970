// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link inside one process (DESIGN.md §2 "In-process"): the world's end and every haptic node's end in one
// object, frames handed over as they are, lockstep by construction. Haptic nodes attach in turn and take the next
// endpoint slots; the first one is the master: its step_world() runs the world node's step on the caller's thread,
// so a whole trial runs on one thread in a fixed order and is bitwise reproducible. The others follow its ticks
// (their step_world() does nothing).

#include "common/link/world_link.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus {

// What the in-process link calls for a world step (the world node implements it).
class WorldStepper {
 public:
  virtual ~WorldStepper() = default;
  virtual void step_world() = 0;
};

// What the in-process link calls for a follower's tick (a following haptic node implements it): false once it has
// stopped (its device left), and it is not called again.
class FollowerStepper {
 public:
  virtual ~FollowerStepper() = default;
  virtual bool follow_tick(std::uint64_t tick) = 0;
};

class InProcessWorldLink final : public WorldLinkServer {
 public:
  explicit InProcessWorldLink(const WorldLinkInfo& info) : info_(info), slots_(kMaxEndpoints) {}

  // The world node whose step_world() the master's step_world(tick) runs; set before the first step.
  void connect(WorldStepper& world) { world_ = &world; }

  // A follower's node, whose follow_tick(t) the master's lead_followers(t) runs; `client` is the end attach() gave it.
  void connect_follower(WorldLinkClient& client, FollowerStepper& node) {
    for (auto& each : clients_) {
      if (each.get() == &client) each->stepper_ = &node;
    }
  }

  // The end for a haptic node with `endpoints` endpoints, on the next free slots; valid as long as the link. Throws
  // std::invalid_argument if the slots would run out.
  WorldLinkClient& attach(std::uint32_t endpoints = 1) {
    if (endpoints == 0 || slots_used_ + endpoints > kMaxEndpoints) {
      throw std::invalid_argument("a world serves at most " + std::to_string(kMaxEndpoints) + " endpoints; " +
                                  std::to_string(slots_used_) + " are taken and " + std::to_string(endpoints) +
                                  " more were asked for");
    }
    clients_.push_back(std::make_unique<Client>(*this, slots_used_, endpoints, clients_.empty()));
    slots_used_ += endpoints;
    return *clients_.back();
  }

  // World end.
  std::uint32_t endpoint_slots() const override { return slots_used_; }
  bool latest_report(std::uint32_t slot, HapticReport& out) override {
    if (slot >= slots_used_ || !slots_[slot].have_report) return false;
    out = slots_[slot].report;
    return true;
  }
  void publish_frame(std::uint32_t slot, const PlaneFrame& frame) override {
    if (slot >= slots_used_) return;
    slots_[slot].frame = frame;
    slots_[slot].frame_pending = true;
  }
  void publish_stats(const LoopStats& stats) override { stats_ = stats; }
  TurnResult wait_turn() override { return TurnResult::shutdown; }  // never waited on: step_world() drives the world
  void finish_turn() override {}
  std::uint64_t rejected_reports() const override { return 0; }

  const LoopStats& world_stats() const { return stats_; }

 private:
  struct Slot {
    PlaneFrame frame{};
    bool frame_pending = false;
    HapticReport report{};
    bool have_report = false;
  };

  class Client final : public WorldLinkClient {
   public:
    Client(InProcessWorldLink& link, std::uint32_t first_slot, std::uint32_t endpoints, bool master)
        : link_(link), first_slot_(first_slot), endpoints_(endpoints), master_(master) {}
    const WorldLinkInfo& info() const override { return link_.info_; }
    std::uint32_t endpoints() const override { return endpoints_; }
    bool receive_frame(EndpointId endpoint, PlaneFrame& out) override {
      if (endpoint >= endpoints_) return false;
      Slot& slot = link_.slots_[first_slot_ + endpoint];
      if (!slot.frame_pending) return false;
      out = slot.frame;
      slot.frame_pending = false;
      return true;
    }
    void publish_report(const HapticReport& report) override {
      if (report.endpoint >= endpoints_) return;
      Slot& slot = link_.slots_[first_slot_ + report.endpoint];
      slot.report = report;
      slot.have_report = true;
    }
    void publish_stats(const LoopStats&) override {}
    bool step_world(std::uint64_t) override {
      if (!master_) return true;
      if (link_.world_ == nullptr) return false;
      link_.world_->step_world();
      return true;
    }
    bool follower() const override { return !master_; }
    bool wait_for_followers(std::uint32_t count) override {
      std::uint32_t present = 0;
      for (const auto& client : link_.clients_) present += client->stepper_ != nullptr ? 1 : 0;
      return present >= count;
    }
    void lead_followers(std::uint64_t tick) override {
      if (!master_) return;
      for (auto& client : link_.clients_) {
        if (client->stepper_ != nullptr && !client->stepper_->follow_tick(tick)) client->stepper_ = nullptr;
      }
    }
    void end_session() override {}
    bool reattach() override { return false; }
    std::uint64_t rejected_frames() const override { return 0; }
    std::uint64_t attaches() const override { return 1; }

    FollowerStepper* stepper_ = nullptr;  // a follower's node, while it follows

   private:
    InProcessWorldLink& link_;
    std::uint32_t first_slot_;
    std::uint32_t endpoints_;
    bool master_;
  };

  WorldLinkInfo info_;
  WorldStepper* world_ = nullptr;
  std::vector<Slot> slots_;  // kMaxEndpoints (~50 KB each: on the heap)
  std::uint32_t slots_used_ = 0;
  std::vector<std::unique_ptr<Client>> clients_;
  LoopStats stats_{};
};

}  // namespace impetus
