// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/shm_world_link.h"

#include "common/link/shm/names.h"
#include "common/link/shm/open_segment.h"
#include "common/link/shm/wire_frames.h"
#include "common/runtime/process.h"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>

namespace impetus {
namespace {

// Longest a lockstep world may take for one step before the master calls it stuck (a big scene's step takes
// milliseconds; this is a hang detector, not a deadline).
constexpr double kTurnTimeout_s = 60.0;

}  // namespace

ShmWorldLinkServer::ShmWorldLinkServer(const std::string& shm, const WorldLinkInfo& info)
    : segment_(Segment<WorldLinkLayout>::create(world_link_name(shm),
                                                [&](WorldLinkLayout& layout) { layout.config = info; })) {}

bool ShmWorldLinkServer::latest_report(HapticReport& out) { return reports_.read(segment_->report, out); }

void ShmWorldLinkServer::publish_frame(const PlaneFrame& frame) {
  encode(frame, frame_wire_);
  if (!segment_->planes.write(frame_wire_, used_bytes(frame_wire_))) ++repairs_;
}

void ShmWorldLinkServer::publish_stats(const LoopStats& stats) {
  if (!segment_->world_stats.write(stats)) ++repairs_;
}

bool ShmWorldLinkServer::latest_haptic_stats(LoopStats& out) {
  segment_->haptic_stats.try_read(haptic_stats_, haptic_stats_sequence_);
  out = haptic_stats_;
  return haptic_stats_sequence_ != 0;
}

TurnResult ShmWorldLinkServer::wait_turn() {
  WorldLinkLayout& link = *segment_;
  // Before a haptic node attaches we wait as long as we are not stopped; once one attached, its death ends the run
  // (nobody would ever give us another turn).
  return link.world_turn.wait_turn([&] {
    if (g_stop_requested.load()) return false;
    const std::int32_t haptic = link.haptic_pid.load();
    return haptic == 0 || process_alive(haptic);
  });
}

void ShmWorldLinkServer::finish_turn() { segment_->world_turn.finish(); }

ShmWorldLinkClient::ShmWorldLinkClient(const std::string& shm, ClockMode clock, double wait_s)
    : name_(world_link_name(shm)), clock_(clock) {
  worlds_.push_back(
      std::make_unique<Segment<WorldLinkLayout>>(open_when_ready<WorldLinkLayout>(name_, wait_s)));
  current_.store(&**worlds_.back(), std::memory_order_release);
  info_ = world().config;
  if (info_.clock != clock) {
    throw std::runtime_error(std::string("the world manager runs --clock ") + to_string(info_.clock) +
                             " but the haptic controller was started with --clock " + to_string(clock));
  }
  world().haptic_pid.store(static_cast<std::int32_t>(getpid()));
}

bool ShmWorldLinkClient::receive_frame(PlaneFrame& out) {
  WorldLinkLayout* current = &world();
  if (current != frames_from_) {  // re-attached to a restarted world: its sequence numbers start afresh
    frames_from_ = current;
    last_frame_sequence_ = 0;
  }
  std::size_t copied = 0;
  if (!current->planes.try_read(frame_wire_, last_frame_sequence_, 4, &copied)) return false;
  if (used_bytes(frame_wire_) > copied || decode(frame_wire_, out) != FrameError::ok) {
    ++rejected_;
    return false;
  }
  return true;
}

void ShmWorldLinkClient::publish_report(const HapticReport& report) {
  encode(report, report_wire_);
  if (!world().report.write(report_wire_, used_bytes(report_wire_))) ++repairs_;
}

void ShmWorldLinkClient::publish_stats(const LoopStats& stats) {
  if (!world().haptic_stats.write(stats)) ++repairs_;
}

bool ShmWorldLinkClient::step_world(std::uint64_t tick) {
  if (!world_alive_) world_alive_ = reattach();
  if (!world_alive_) return false;
  WorldLinkLayout& link = world();
  link.world_turn.give(tick);
  const TurnResult result = link.world_turn.wait_done([&] { return worlds_.back()->creator_alive(); }, kTurnTimeout_s);
  if (result != TurnResult::ok) {
    std::fprintf(stderr, "haptic_controller: the world manager is lost: %s; keeping its last planes\n",
                 to_string(result));
    world_alive_ = false;
  }
  return world_alive_;
}

void ShmWorldLinkClient::end_session() { world().world_turn.request_shutdown(); }

bool ShmWorldLinkClient::world_alive() const { return worlds_.back()->creator_alive(); }

bool ShmWorldLinkClient::reattach() {
  if (worlds_.back()->creator_alive()) return false;
  try {
    auto fresh = std::make_unique<Segment<WorldLinkLayout>>(Segment<WorldLinkLayout>::open(name_));
    if (!fresh->creator_alive() || (*fresh)->config.clock != clock_) return false;
    (*fresh)->haptic_pid.store(static_cast<std::int32_t>(getpid()));
    worlds_.push_back(std::move(fresh));
    current_.store(&**worlds_.back(), std::memory_order_release);
    attaches_.fetch_add(1);
    std::fprintf(stderr, "haptic_controller: re-attached to a restarted world manager\n");
    return true;
  } catch (const SegmentError&) {
    return false;  // not (yet) there: the last planes stay in force meanwhile
  }
}

}  // namespace impetus
