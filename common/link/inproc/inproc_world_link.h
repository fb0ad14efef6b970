// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link inside one process (docs/architecture.md §2 "In-process"): the world's end and every haptic node's end
// in one object, lockstep by construction. Haptic nodes attach in turn and take the next endpoint slots; the first one
// is the master: its step_world() runs the world node's step on the caller's thread, so a whole trial runs on one
// thread in a fixed order and is bitwise reproducible. The others follow its ticks (their step_world() does nothing).
//
// Delay line (docs/architecture.md §3): the link can hold frames and reports back by d haptic ticks each way, to
// measure what network latency does to a coupling, reproducibly. Time on the link is the tick count the reports carry
// (HapticReport::tick: a servo's report of its k-th tick carries k); in an in-process lockstep run every servo starts
// with the master and ticks once per master tick, so the counts of all nodes are one clock.
//   - A haptic node is "at tick k" from its publishing the reports of its k-th tick until it publishes the next ones;
//     the world is "at tick k" when it steps after the reports of tick k (the newest tick any report carries).
//   - A frame the world publishes at tick k reaches its haptic node at tick k + d, not before: the node takes it at the
//     first receive_frame() it makes at tick ≥ k + d (the master receives after every tick, a follower before its
//     next one), so the servo first renders it on the next tick, as it renders a frame of tick k on tick k + 1
//     with no delay.
//   - The world stepping at tick k reads, per slot, the newest report of a tick ≤ k − d, or none while there is none.
// d = 0 is the link without delay: the world reads the reports of its own tick and its frames are taken at once, so a
// trial is bitwise the trial of a link with no delay line. Each slot has its own lines, sized when a haptic node
// attaches (frames: d/n + 3 for n ticks per world step; reports: d + 2); publishing and receiving never allocate, lock
// or throw. A full line drops its oldest entry and counts it (dropped()); that happens only when a node stops taking
// its frames. Not thread-safe: the lockstep run's one thread uses every end.
//
// Loss (common/link/link_loss.h): the link can also lose frames and reports, each direction of each slot by its own seeded
// Gilbert–Elliott stream. A lost frame never reaches its node (it keeps the frame before); a lost report never reaches
// the world (it reads the newest report that did arrive, whose running totals hold the lost one's impulse). Counted in
// lost_frames() and lost_reports(). No loss is the link without a loss model, bit for bit.

#include "common/link/inproc/delay_line.h"
#include "common/link/link_loss.h"
#include "common/link/world_link.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus {

// The one-way delay of an in-process link, the same both ways.
struct InProcessLinkDelay {
  std::uint64_t delay_ticks = 0;  // d, in haptic ticks
  // n = T_w / T (LockstepSchedule::ticks_per_world_step): the world sends one frame per slot each n ticks, which sizes
  // the frame lines. Too small a value only wastes memory.
  std::uint64_t ticks_per_world_step = 1;
};

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
  // Throws std::invalid_argument if delay.ticks_per_world_step is 0.
  explicit InProcessWorldLink(const WorldLinkInfo& info, InProcessLinkDelay delay = {}, LinkLoss loss = {})
      : info_(info), delay_(delay), loss_(loss), slots_(kMaxEndpoints) {
    if (delay.ticks_per_world_step == 0) {
      throw std::invalid_argument("in-process link: ticks_per_world_step must be 1 or more, not 0");
    }
  }

  // The world node whose step_world() the master's step_world(tick) runs; set before the first step.
  void connect(WorldStepper& world) { world_ = &world; }

  // A follower's node, whose follow_tick(t) the master's lead_followers(t) runs; `client` is the end attach() gave it.
  void connect_follower(WorldLinkClient& client, FollowerStepper& node) {
    for (auto& each : clients_) {
      if (each.get() == &client) each->stepper_ = &node;
    }
  }

  // The end for a haptic node with `endpoints` endpoints, on the next free slots; valid as long as the link. Sizes the
  // slots' delay lines (allocates). Throws std::invalid_argument if the slots would run out.
  WorldLinkClient& attach(std::uint32_t endpoints = 1) {
    if (endpoints == 0 || slots_used_ + endpoints > kMaxEndpoints) {
      throw std::invalid_argument("a world serves at most " + std::to_string(kMaxEndpoints) + " endpoints; " +
                                  std::to_string(slots_used_) + " are taken and " + std::to_string(endpoints) +
                                  " more were asked for");
    }
    // Frames in flight to a node: those sent at ticks (k − d, k + 1] (a follower takes them one tick after the
    // master), at most d/n + 2 world steps, plus the newest due one. Reports in flight: one per tick of (k − d, k],
    // plus the newest due one; one more for slack.
    const std::size_t frame_capacity = delay_.delay_ticks / delay_.ticks_per_world_step + 3;
    const std::size_t report_capacity = delay_.delay_ticks + 2;
    for (std::uint32_t k = slots_used_; k < slots_used_ + endpoints; ++k) {
      slots_[k].frames.reset(delay_.delay_ticks, frame_capacity);
      slots_[k].reports.reset(delay_.delay_ticks, report_capacity);
      slots_[k].frame_loss = LossProcess(loss_, 2 * k);
      slots_[k].report_loss = LossProcess(loss_, 2 * k + 1);
    }
    clients_.push_back(std::make_unique<Client>(*this, slots_used_, endpoints, clients_.empty()));
    slots_used_ += endpoints;
    return *clients_.back();
  }

  // World end.
  std::uint32_t endpoint_slots() const override { return slots_used_; }
  // The newest report of slot `slot` sent at a tick ≤ (the world's tick) − d.
  bool latest_report(std::uint32_t slot, HapticReport& out) override {
    if (slot >= slots_used_) return false;
    const auto due = slots_[slot].reports.take_newest_due(now_ticks_);
    if (due.value == nullptr) return false;
    copy_used(*due.value, out);
    return true;
  }
  // Sent at the world's tick: the newest tick any report carries.
  void publish_frame(std::uint32_t slot, const PlaneFrame& frame) override {
    if (slot >= slots_used_ || slots_[slot].frame_loss.lose()) return;
    slots_[slot].frames.push(now_ticks_, frame);
  }
  void publish_stats(const LoopStats& stats) override { stats_ = stats; }
  TurnResult wait_turn() override { return TurnResult::shutdown; }  // never waited on: step_world() drives the world
  void finish_turn() override {}
  std::uint64_t rejected_reports() const override { return 0; }

  const LoopStats& world_stats() const { return stats_; }
  std::uint64_t delay_ticks() const { return delay_.delay_ticks; }
  // Frames and reports that full delay lines pushed out over the run (0 unless a line was sized too small or a node
  // stopped taking its frames).
  std::uint64_t dropped() const {
    std::uint64_t total = 0;
    for (std::uint32_t k = 0; k < slots_used_; ++k) total += slots_[k].frames.dropped() + slots_[k].reports.dropped();
    return total;
  }
  // Frames and reports the loss model lost over the run.
  std::uint64_t lost_frames() const {
    std::uint64_t total = 0;
    for (std::uint32_t k = 0; k < slots_used_; ++k) total += slots_[k].frame_loss.lost();
    return total;
  }
  std::uint64_t lost_reports() const {
    std::uint64_t total = 0;
    for (std::uint32_t k = 0; k < slots_used_; ++k) total += slots_[k].report_loss.lost();
    return total;
  }

 private:
  struct Slot {
    DelayLine<PlaneFrame> frames;        // world → haptic
    DelayLine<HapticReport> reports;     // haptic → world
    LossProcess frame_loss;
    LossProcess report_loss;
    std::uint64_t frame_taken = 0;       // sequence of the last frame its node took (0: none yet)
  };

  class Client final : public WorldLinkClient {
   public:
    Client(InProcessWorldLink& link, std::uint32_t first_slot, std::uint32_t endpoints, bool master)
        : link_(link), first_slot_(first_slot), endpoints_(endpoints), master_(master) {}
    const WorldLinkInfo& info() const override { return link_.info_; }
    std::uint32_t endpoints() const override { return endpoints_; }
    // The newest frame due at this node's tick, if it has not taken it yet.
    bool receive_frame(EndpointId endpoint, PlaneFrame& out) override {
      if (endpoint >= endpoints_) return false;
      Slot& slot = link_.slots_[first_slot_ + endpoint];
      const auto due = slot.frames.take_newest_due(now_ticks_);
      if (due.value == nullptr || due.sequence == slot.frame_taken) return false;
      copy_used(*due.value, out);
      slot.frame_taken = due.sequence;
      return true;
    }
    void publish_report(const HapticReport& report) override {
      if (report.endpoint >= endpoints_) return;
      if (report.tick > now_ticks_) now_ticks_ = report.tick;
      if (report.tick > link_.now_ticks_) link_.now_ticks_ = report.tick;
      Slot& slot = link_.slots_[first_slot_ + report.endpoint];
      DelayLine<HapticReport>& reports = slot.reports;
      if (!slot.report_loss.lose()) reports.push(report.tick, report);
      // Reports the world can no longer need give way now, so the line holds only those in flight: the world, at a
      // tick ≥ this one, will want a report at least this new.
      reports.take_newest_due(link_.now_ticks_);
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
    std::uint64_t now_ticks_ = 0;  // this node's tick: the newest its reports carried
  };

  WorldLinkInfo info_;
  InProcessLinkDelay delay_;
  LinkLoss loss_;
  WorldStepper* world_ = nullptr;
  std::vector<Slot> slots_;  // kMaxEndpoints; their lines are sized at attach
  std::uint32_t slots_used_ = 0;
  std::vector<std::unique_ptr<Client>> clients_;
  std::uint64_t now_ticks_ = 0;  // the world's tick: the newest any report carried
  LoopStats stats_{};
};

}  // namespace impetus
