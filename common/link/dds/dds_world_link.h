// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world link over DDS (docs/architecture.md §2), for a world and its haptic controllers on different machines. Real
// time only: lockstep turns stay a shared-memory (or in-process) matter. Each 1 kHz servo stays on its device's
// machine; only plane frames, reports and the world's info travel (topics and QoS in impetus_link.idl).
//
// Who serves whom. A controller names itself with a random client id; each of its endpoints is a (client id,
// endpoint) key. The world gives a key the first free endpoint slot when its first report arrives, and publishes the
// slot table in its info, so a controller knows it was served (or refused: all slots taken). A slot is free again when
// its controller leaves (its writer disposes the key) or its process stops answering (DDS liveliness, kDdsLease_s).
//
// What the servo thread touches. DDS writes and reads allocate and lock, so the client runs two threads of its own: a
// receiver that takes frames and the info off DDS into per-endpoint seqlock channels, and a sender that publishes the
// newest report of each endpoint as soon as it sees it (it looks every 250 µs). receive_frame() and publish_report()
// only touch those channels: allocation-free, lock-free, no system call. The world's end runs on the world's thread and calls DDS directly.
//
// One world per controller. Frames carry their world's id and reports the id of the world they are for. A controller
// follows the first world that answers; a second live world on the partition is reported and ignored (its frames are
// dropped, and a world ignores reports for another world), and takes the followed world's place only once that one
// has gone (left, or silent past its lease).
//
// Loss and repetition. Frames are best effort (a lost one is replaced by the next step's), reports reliable keep-last-1
// and in any case running totals: the world applies total − applied, so a lost, repeated or reordered report changes
// nothing it applies once a newer one arrives.

#include "common/link/dds/dds_participant.h"
#include "common/link/world_link.h"

#include <memory>

namespace impetus {

class DdsWorldLinkServer final : public WorldLinkServer {
 public:
  // Joins the domain and publishes `info` (clock must be realtime: throws std::invalid_argument otherwise).
  DdsWorldLinkServer(const DdsLinkOptions& options, const WorldLinkInfo& info);
  ~DdsWorldLinkServer() override;

  std::uint32_t endpoint_slots() const override { return kMaxEndpoints; }
  bool latest_report(std::uint32_t slot, HapticReport& out) override;
  void publish_frame(std::uint32_t slot, const PlaneFrame& frame) override;
  void publish_stats(const LoopStats&) override {}
  bool latest_haptic_stats(std::uint32_t slot, LoopStats& out) override;
  TurnResult wait_turn() override { return TurnResult::shutdown; }  // real time only
  void finish_turn() override {}
  std::uint64_t rejected_reports() const override;

  // Keys refused because every slot was taken, and slots freed because their controller left or went silent.
  std::uint64_t refused_endpoints() const;
  std::uint64_t released_slots() const;
  // Reports of controllers that follow another world on the partition: never applied here.
  std::uint64_t foreign_reports() const;
  std::string name() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

class DdsWorldLinkClient final : public WorldLinkClient {
 public:
  // Joins the domain, waits up to `wait_s` for a world and for it to give each of `endpoints` endpoints a slot.
  // Throws std::invalid_argument for a lockstep clock or a bad count, std::runtime_error if no world answers in time
  // (naming the domain and partition) or the world has too few free slots (with the numbers).
  DdsWorldLinkClient(const DdsLinkOptions& options, ClockMode clock, double wait_s, std::uint32_t endpoints = 1);
  // Stops the threads and leaves: the world frees the slots at once.
  ~DdsWorldLinkClient() override;

  const WorldLinkInfo& info() const override;
  std::uint32_t endpoints() const override;
  bool receive_frame(EndpointId endpoint, PlaneFrame& out) override;
  void publish_report(const HapticReport& report) override;
  // To the world (for its viewers), through the sender thread: a seqlock write here.
  void publish_stats(const LoopStats& stats) override;
  bool step_world(std::uint64_t) override { return false; }  // real time only
  void end_session() override {}
  bool world_alive() const override;
  bool reattach() override;
  std::uint64_t rejected_frames() const override;
  std::uint64_t attaches() const override;

  std::uint64_t client_id() const;
  // Reports handed to DDS by the sender thread (each new one, and an unchanged one again every 0.1 s).
  std::uint64_t reports_sent() const;
  // Other worlds seen live on the partition while this controller followed its own (refused, not adopted), and the
  // frames they sent it (dropped).
  std::uint64_t other_worlds() const;
  std::uint64_t foreign_frames() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace impetus
