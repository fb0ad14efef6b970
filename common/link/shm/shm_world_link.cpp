// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/shm_world_link.h"

#include "common/link/shm/names.h"
#include "common/link/shm/open_segment.h"
#include "common/link/shm/wire_frames.h"
#include "common/runtime/process.h"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

// Longest a lockstep world may take for one step before the master calls it stuck (a big scene's step takes
// milliseconds; this is a hang detector, not a deadline).
constexpr double kTurnTimeout_s = 60.0;

}  // namespace

ShmWorldLinkServer::ShmWorldLinkServer(const std::string& shm, const WorldLinkInfo& info)
    : segment_(Segment<WorldLinkLayout>::create(world_link_name(shm),
                                                [&](WorldLinkLayout& layout) { layout.config = info; })),
      slots_(kMaxEndpoints) {}

bool ShmWorldLinkServer::latest_report(std::uint32_t slot, HapticReport& out) {
  return slot < kMaxEndpoints && slots_[slot].reports.read(segment_->slots[slot].report, out);
}

void ShmWorldLinkServer::publish_frame(std::uint32_t slot, const PlaneFrame& frame) {
  if (slot >= kMaxEndpoints) return;
  encode(frame, frame_wire_);
  if (!segment_->slots[slot].planes.write(frame_wire_, used_bytes(frame_wire_))) ++repairs_;
}

void ShmWorldLinkServer::publish_stats(const LoopStats& stats) {
  if (!segment_->world_stats.write(stats)) ++repairs_;
}

bool ShmWorldLinkServer::latest_haptic_stats(std::uint32_t slot, LoopStats& out) {
  if (slot >= kMaxEndpoints) return false;
  SlotReader& reader = slots_[slot];
  segment_->slots[slot].haptic_stats.try_read(reader.stats, reader.stats_sequence);
  out = reader.stats;
  return reader.stats_sequence != 0;
}

std::uint64_t ShmWorldLinkServer::rejected_reports() const {
  std::uint64_t rejected = 0;
  for (const SlotReader& reader : slots_) rejected += reader.reports.rejected();
  return rejected;
}

TurnResult ShmWorldLinkServer::wait_turn() {
  WorldLinkLayout& link = *segment_;
  // Before the master attaches we wait as long as we are not stopped; once one attached, its death ends the run
  // (nobody would ever give us another turn).
  return link.world_turn.wait_turn([&] {
    if (g_stop_requested.load()) return false;
    const std::int32_t master = link.master_pid.load();
    return master == 0 || process_alive(master);
  });
}

void ShmWorldLinkServer::finish_turn() { segment_->world_turn.finish(); }

namespace {

// Takes `word` for this process if it is free (0) or held by a process that is gone. A word this process holds is
// not free: two clients in one process take different slots.
bool take(std::atomic<std::int32_t>& word, std::int32_t self) {
  std::int32_t holder = word.load();
  while (holder == 0 || (holder != self && !process_alive(holder))) {
    if (word.compare_exchange_weak(holder, self)) return true;
  }
  return false;
}

}  // namespace

std::unique_ptr<ShmWorldLinkClient::Attachment> ShmWorldLinkClient::attach(
    std::unique_ptr<Segment<WorldLinkLayout>> segment) const {
  WorldLinkLayout& link = **segment;
  const auto self = static_cast<std::int32_t>(getpid());
  auto attachment = std::make_unique<Attachment>();
  std::uint32_t taken = 0;
  for (std::uint32_t slot = 0; slot < kMaxEndpoints && taken < endpoints_; ++slot) {
    if (take(link.slots[slot].owner_pid, self)) attachment->slots[taken++] = slot;
  }
  if (taken < endpoints_) {
    for (std::uint32_t k = 0; k < taken; ++k) link.slots[attachment->slots[k]].owner_pid.store(0);
    throw std::runtime_error("the world at '" + name_ + "' has " + std::to_string(taken) + " free endpoint slot(s) of " +
                             std::to_string(kMaxEndpoints) + "; this controller needs " + std::to_string(endpoints_));
  }
  if (clock_ == ClockMode::lockstep && !take(link.master_pid, self)) {
    // Another controller leads: follow its ticks. Its turn is reset before the mark is set, so the master never
    // gives a turn on words a previous holder left behind.
    EndpointSlotLayout& first = link.slots[attachment->slots[0]];
    first.follower_turn.reset();
    first.follower.store(1, std::memory_order_release);
    attachment->follower = true;
  }
  attachment->segment = std::move(segment);
  return attachment;
}

ShmWorldLinkClient::ShmWorldLinkClient(const std::string& shm, ClockMode clock, double wait_s,
                                       std::uint32_t endpoints)
    : name_(world_link_name(shm)), clock_(clock), endpoints_(endpoints) {
  if (endpoints == 0 || endpoints > kMaxEndpoints) {
    throw std::invalid_argument("a haptic controller serves 1 to " + std::to_string(kMaxEndpoints) +
                                " endpoints, not " + std::to_string(endpoints));
  }
  auto segment = std::make_unique<Segment<WorldLinkLayout>>(open_when_ready<WorldLinkLayout>(name_, wait_s));
  info_ = (*segment)->config;
  if (info_.clock != clock) {
    throw std::runtime_error(std::string("the world manager runs --clock ") + to_string(info_.clock) +
                             " but the haptic controller was started with --clock " + to_string(clock));
  }
  worlds_.push_back(attach(std::move(segment)));
  current_.store(worlds_.back().get(), std::memory_order_release);
}

ShmWorldLinkClient::~ShmWorldLinkClient() {
  const auto self = static_cast<std::int32_t>(getpid());
  for (const auto& attachment : worlds_) {
    WorldLinkLayout& link = **attachment->segment;
    if (attachment->follower) link.slots[attachment->slots[0]].follower.store(0, std::memory_order_release);
    for (std::uint32_t k = 0; k < endpoints_; ++k) {
      std::int32_t expected = self;
      link.slots[attachment->slots[k]].owner_pid.compare_exchange_strong(expected, 0);
    }
    std::int32_t expected = self;
    link.master_pid.compare_exchange_strong(expected, 0);
  }
}

bool ShmWorldLinkClient::receive_frame(EndpointId endpoint, PlaneFrame& out) {
  if (endpoint >= endpoints_) return false;
  const Attachment& attachment = current();
  if (&attachment != frames_from_) {  // re-attached to a restarted world: its sequence numbers start afresh
    frames_from_ = &attachment;
    last_frame_sequence_.fill(0);
  }
  std::size_t copied = 0;
  const EndpointSlotLayout& slot = (*attachment.segment)->slots[attachment.slots[endpoint]];
  if (!slot.planes.try_read(frame_wire_, last_frame_sequence_[endpoint], 4, &copied)) return false;
  if (used_bytes(frame_wire_) > copied || decode(frame_wire_, out) != FrameError::ok) {
    ++rejected_;
    return false;
  }
  return true;
}

void ShmWorldLinkClient::publish_report(const HapticReport& report) {
  if (report.endpoint >= endpoints_) return;
  const Attachment& attachment = current();
  encode(report, report_wire_);
  EndpointSlotLayout& slot = (*attachment.segment)->slots[attachment.slots[report.endpoint]];
  if (!slot.report.write(report_wire_, used_bytes(report_wire_))) ++repairs_;
}

void ShmWorldLinkClient::publish_stats(const LoopStats& stats) {
  const Attachment& attachment = current();
  if (!(*attachment.segment)->slots[attachment.slots[0]].haptic_stats.write(stats)) ++repairs_;
}

bool ShmWorldLinkClient::step_world(std::uint64_t tick) {
  if (!world_alive_) world_alive_ = reattach();
  if (!world_alive_) return false;
  WorldLinkLayout& link = world();
  link.world_turn.give(tick);
  const TurnResult result =
      link.world_turn.wait_done([&] { return worlds_.back()->segment->creator_alive(); }, kTurnTimeout_s);
  if (result != TurnResult::ok) {
    std::fprintf(stderr, "haptic_controller: the world manager is lost: %s; keeping its last planes\n",
                 to_string(result));
    world_alive_ = false;
  }
  return world_alive_;
}

void ShmWorldLinkClient::end_session() {
  WorldLinkLayout& link = world();
  if (current().follower) {
    // A follower leaves: the master stops giving it turns.
    link.slots[current().slots[0]].follower.store(0, std::memory_order_release);
    return;
  }
  link.world_turn.request_shutdown();
  for (EndpointSlotLayout& slot : link.slots) {
    if (slot.follower.load(std::memory_order_acquire) == 1) slot.follower_turn.request_shutdown();
  }
}

bool ShmWorldLinkClient::wait_for_followers(std::uint32_t count) {
  for (bool said = false;; said = true) {
    std::uint32_t present = 0;
    for (const EndpointSlotLayout& slot : world().slots) {
      if (slot.follower.load(std::memory_order_acquire) == 1 && process_alive(slot.owner_pid.load())) ++present;
    }
    if (present >= count) return true;
    if (g_stop_requested.load()) return false;
    if (!said) {
      std::fprintf(stderr, "haptic_controller: waiting for %u more controller(s) to follow this lockstep run\n",
                   count - present);
    }
    usleep(1'000);
  }
}

void ShmWorldLinkClient::lead_followers(std::uint64_t tick) {
  if (current().follower) return;
  WorldLinkLayout& link = world();
  for (EndpointSlotLayout& slot : link.slots) {
    if (slot.follower.load(std::memory_order_acquire) != 1) continue;
    const std::int32_t holder = slot.owner_pid.load();
    slot.follower_turn.give(tick);
    const TurnResult result = slot.follower_turn.wait_done(
        [&] { return holder != 0 && process_alive(holder) && slot.follower.load() == 1; }, kTurnTimeout_s);
    if (result != TurnResult::ok) {
      // Gone, stuck or left mid-turn: no more turns for it (its endpoints' last reports stay; the world drops them
      // as it drops any endpoint that stopped reporting).
      slot.follower.store(0, std::memory_order_release);
      std::fprintf(stderr, "haptic_controller: a following haptic controller (pid %d) left the lockstep run: %s\n",
                   holder, to_string(result));
    }
  }
}

TurnResult ShmWorldLinkClient::wait_follower_turn(std::uint64_t& tick) {
  const Attachment& attachment = current();
  if (!attachment.follower) return TurnResult::shutdown;
  WorldLinkLayout& link = **attachment.segment;
  EndpointSlotLayout& slot = link.slots[attachment.slots[0]];
  const TurnResult result = slot.follower_turn.wait_turn([&] {
    if (g_stop_requested.load()) return false;
    const std::int32_t master = link.master_pid.load();
    return master != 0 && process_alive(master) && attachment.segment->creator_alive();
  });
  if (result == TurnResult::ok) tick = slot.follower_turn.tick();
  return result;
}

void ShmWorldLinkClient::finish_follower_turn() {
  const Attachment& attachment = current();
  if (attachment.follower) (*attachment.segment)->slots[attachment.slots[0]].follower_turn.finish();
}

bool ShmWorldLinkClient::world_alive() const { return worlds_.back()->segment->creator_alive(); }

bool ShmWorldLinkClient::reattach() {
  if (worlds_.back()->segment->creator_alive()) return false;
  try {
    auto fresh = std::make_unique<Segment<WorldLinkLayout>>(Segment<WorldLinkLayout>::open(name_));
    if (!fresh->creator_alive() || (*fresh)->config.clock != clock_) return false;
    worlds_.push_back(attach(std::move(fresh)));
    current_.store(worlds_.back().get(), std::memory_order_release);
    attaches_.fetch_add(1);
    std::fprintf(stderr, "haptic_controller: re-attached to a restarted world manager\n");
    return true;
  } catch (const SegmentError&) {
    return false;  // not (yet) there: the last planes stay in force meanwhile
  } catch (const std::runtime_error& error) {
    // The restarted world's slots are all taken (other controllers came first): say so, and keep looking.
    std::fprintf(stderr, "haptic_controller: cannot re-attach: %s\n", error.what());
    return false;
  }
}

}  // namespace impetus
