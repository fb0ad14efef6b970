// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link (docs/architecture.md §1, §2): plane frames from the world to each endpoint, running impulse totals
// and the finger back. Two ends, each an interface the nodes talk through; the transports (shared memory, in-process)
// encode, seal and validate, so a node only ever sees contract frames that passed validation.
//
// Threading: each end is used by its node's loop thread, except WorldLinkClient::reattach(), which a real-time haptic
// node calls from its supervisor thread while the servo thread keeps reading (implementations make that safe).

#include "common/contract/frames.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/loop_stats.h"

#include <cstdint>

namespace impetus {

// What the world tells every haptic side once, at attach: its schedule and coupling. Trivially copyable (the shared
// memory transport keeps it in its segment).
struct WorldLinkInfo {
  double world_rate_hz = 0.0;
  double world_period_s = 0.0;
  std::uint64_t phase_ticks = 0;  // lockstep: world step i happens at haptic tick i·n + phase_ticks
  ClockMode clock = ClockMode::realtime;
  Coupling coupling = Coupling::impulse;
};

// The world node's end. It serves endpoint slots 0..endpoint_slots()−1; each slot carries one endpoint's reports in
// and its frames out, whichever haptic controller holds it (slots are taken in order as controllers attach).
class WorldLinkServer {
 public:
  virtual ~WorldLinkServer() = default;

  // How many endpoint slots the link has (at most kMaxEndpoints).
  virtual std::uint32_t endpoint_slots() const = 0;
  // The newest valid report in slot `slot` since the world started (whether or not it is new since the last call);
  // false if none has arrived yet. Invalid reports are dropped and counted.
  virtual bool latest_report(std::uint32_t slot, HapticReport& out) = 0;
  // The frame for the endpoint in slot `slot`.
  virtual void publish_frame(std::uint32_t slot, const PlaneFrame& frame) = 0;
  virtual void publish_stats(const LoopStats& stats) = 0;
  // The loop statistics of the haptic controller in slot `slot` (for viewers); false if none or the transport has
  // none.
  virtual bool latest_haptic_stats(std::uint32_t /*slot*/, LoopStats& /*out*/) { return false; }

  // Lockstep follower: waits for the master's go for the next world step. ok: step now, then finish_turn();
  // anything else ends the run (shutdown: the session ended; peer_gone: the master died or a stop was requested).
  virtual TurnResult wait_turn() = 0;
  virtual void finish_turn() = 0;

  virtual std::uint64_t rejected_reports() const = 0;
  // Writes that found their channel's sequence word odd at rest (scribbled, or a writer killed mid-write) and repaired
  // it (seqlock.h); 0 for transports without sequence words.
  virtual std::uint64_t channel_repairs() const { return 0; }
};

// A haptic node's end, for its endpoints 0..endpoints()−1 (one per finger of its device).
class WorldLinkClient {
 public:
  virtual ~WorldLinkClient() = default;

  virtual const WorldLinkInfo& info() const = 0;
  virtual std::uint32_t endpoints() const = 0;
  // The newest valid frame for `endpoint` published since the last call; false if none. A restarted world's frames
  // follow on (PlaneFrame::world_session tells them apart). Invalid frames are dropped and counted.
  virtual bool receive_frame(EndpointId endpoint, PlaneFrame& out) = 0;
  // Publishes the report of endpoint report.endpoint (< endpoints()).
  virtual void publish_report(const HapticReport& report) = 0;
  virtual void publish_stats(const LoopStats& stats) = 0;

  // Lockstep master: the world takes its step for haptic tick `tick`; false if the world is gone (its last frames
  // stay in force until reattach() finds a new one). A follower (another controller in a lockstep run whose master
  // steps the world) returns true at once.
  virtual bool step_world(std::uint64_t tick) = 0;
  // Lockstep master: ends the session; a waiting world returns from wait_turn() with `shutdown`, and so does every
  // follower waiting in wait_follower_turn().
  virtual void end_session() = 0;

  // Several controllers on one lockstep world (docs/architecture.md §3): the first is the master, the others follow its
  // ticks. Whether this end is a follower.
  virtual bool follower() const { return false; }
  // Master, before its first tick: waits until `count` followers have attached (a lockstep run of several users
  // starts when they are all there); false if a stop was requested first.
  virtual bool wait_for_followers(std::uint32_t count) { return count == 0; }
  // Master, every tick after its own: each follower does tick `tick`, in slot order, before the world may step.
  virtual void lead_followers(std::uint64_t /*tick*/) {}
  // Follower: waits for the master's next tick. ok: do tick `tick`, then finish_follower_turn(); shutdown: the
  // session ended; peer_gone: the master died (or a stop was requested).
  virtual TurnResult wait_follower_turn(std::uint64_t& /*tick*/) { return TurnResult::shutdown; }
  virtual void finish_follower_turn() {}
  // Whether the world is still there (its process alive); a transport that cannot tell says true. A lockstep world
  // that died after its last step, before the session ended, is noticed here.
  virtual bool world_alive() const { return true; }

  // Not real time: if the world died and a new one took its place, follow it. True if it switched.
  virtual bool reattach() = 0;

  virtual std::uint64_t rejected_frames() const = 0;
  virtual std::uint64_t attaches() const = 0;  // 1 + re-attachments
  // Writes that found their channel's sequence word odd at rest (scribbled, or a writer killed mid-write) and repaired
  // it (seqlock.h); 0 for transports without sequence words.
  virtual std::uint64_t channel_repairs() const { return 0; }
};

}  // namespace impetus
