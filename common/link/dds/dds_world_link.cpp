// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_world_link.h"

#include "common/link/dds/dds_codec.h"
#include "common/link/dds/dds_entities.h"
#include "common/link/delay_stage.h"
#include "common/link/shm/seqlock.h"
#include "common/runtime/message_text.h"
#include "common/runtime/process.h"

#include <dds/dds.h>

#include <array>
#include <atomic>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace impetus {
namespace {

constexpr const char* kFrameTopic = "impetus_plane_frame";
constexpr const char* kReportTopic = "impetus_haptic_report";
constexpr const char* kInfoTopic = "impetus_world_info";
constexpr const char* kStatsTopic = "impetus_haptic_stats";

// The sender looks for a new report of each endpoint this often and publishes it: a quarter of the servo's period, so
// a report leaves at most a quarter period after the servo wrote it (polling at the servo's own period would add a
// fixed phase of up to a whole period). It repeats an unchanged report after kReportRepeat_s, so one lost before the
// world matched the writer (the first, which asks for a slot) is sent again.
constexpr std::chrono::microseconds kSendPeriod{250};
constexpr double kReportRepeat_s = 0.1;
// How long a stopping controller waits for the world to acknowledge its last reports (a live world on a LAN answers
// within milliseconds; a world that went away is not waited for).
constexpr dds_duration_t kFinalAckWait = DDS_MSECS(500);
// How long the receiver blocks before it looks at its stop flag (a guard condition wakes it sooner).
constexpr dds_duration_t kReceiveWait = DDS_MSECS(100);
// Samples taken per call: more than a world's endpoints' frames in one period.
constexpr std::uint32_t kTakeBatch = 16;

using Key = std::pair<std::uint64_t, std::uint32_t>;  // (client id, client endpoint)

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Room in a delay stage for what arrives in `delay_ns` at `rate_hz` at most, and a few more.
std::size_t stage_capacity(std::int64_t delay_ns, double rate_hz) {
  return static_cast<std::size_t>(static_cast<double>(delay_ns) * 1e-9 * rate_hz) + 8;
}
// Reports: one per servo tick at most (2 kHz covers the default 1 kHz servo twice over); a faster servo's in-flight
// reports beyond that are dropped oldest first, which only means the world skips one (running totals).
constexpr double kStagedReportRate_Hz = 2000.0;
// Frames: one per world step; 100 Hz worlds and slower keep every frame in flight.
constexpr double kStagedFrameRate_Hz = 100.0;

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// The world's end.

struct DdsWorldLinkServer::State {
  struct Slot {
    Key key{0, 0};  // client id 0: free
    HapticReport latest{};
    bool have = false;
    LoopStats stats{};
    bool have_stats = false;
  };

  State(const DdsLinkOptions& options, const WorldLinkInfo& link_info)
      : participant(options),
        info(link_info),
        world_id(new_session_id()),
        delay_ns(static_cast<std::int64_t>(options.delay_s * 1e9)),
        loss(options.loss),
        staged(options.delay_s > 0.0 || options.loss.rate > 0.0) {
    const dds_entity_t publisher = make_publisher(participant.handle(), options.partition);
    const dds_entity_t subscriber = make_subscriber(participant.handle(), options.partition);
    frame_writer = make_writer(publisher, make_topic(participant.handle(), &impetus_dds_PlaneFrame_desc, kFrameTopic),
                               Delivery::best_effort);
    report_reader = make_reader(
        subscriber, make_topic(participant.handle(), &impetus_dds_HapticReport_desc, kReportTopic), Delivery::reliable);
    info_writer = make_writer(publisher, make_topic(participant.handle(), &impetus_dds_WorldInfo_desc, kInfoTopic),
                              Delivery::reliable_durable);
    stats_reader = make_reader(
        subscriber, make_topic(participant.handle(), &impetus_dds_HapticStats_desc, kStatsTopic), Delivery::best_effort);
    for (std::uint32_t k = 0; k < kTakeBatch; ++k) buffers[k] = &*samples[k];
    publish_info();
  }

  void publish_info() {
    impetus_dds_WorldInfo sample{};
    sample.world_id = world_id;
    sample.world_rate_hz = info.world_rate_hz;
    sample.world_period_s = info.world_period_s;
    sample.phase_ticks = info.phase_ticks;
    sample.clock = static_cast<std::uint32_t>(info.clock);
    sample.coupling = static_cast<std::uint32_t>(info.coupling);
    for (std::uint32_t k = 0; k < kMaxEndpoints; ++k) {
      sample.slots[k].client_id = slots[k].key.first;
      sample.slots[k].client_endpoint = slots[k].key.second;
    }
    dds_check(dds_write(info_writer, &sample), "cannot publish the world's info");
  }

  int slot_of(const Key& key) const {
    for (std::uint32_t k = 0; k < kMaxEndpoints; ++k) {
      if (slots[k].key == key) return static_cast<int>(k);
    }
    return -1;
  }

  // A key seen for the first time takes the first free slot; -1 if none is free.
  int take_slot(const Key& key) {
    for (std::uint32_t k = 0; k < kMaxEndpoints; ++k) {
      if (slots[k].key.first == 0) {
        slots[k] = Slot{key, HapticReport{}, false, LoopStats{}, false};
        if (staged) stages[k].reset(delay_ns, stage_capacity(delay_ns, kStagedReportRate_Hz), loss, 2 * k + 1);
        std::fprintf(stderr, "world_manager: endpoint slot %u serves controller %016llx, its endpoint %u\n", k,
                     static_cast<unsigned long long>(key.first), key.second);
        publish_info();
        return static_cast<int>(k);
      }
    }
    if (refused_keys.insert(key).second) {
      std::fprintf(stderr,
                   "world_manager: a controller (client %016llx) asked for an endpoint slot but all %u are taken\n",
                   static_cast<unsigned long long>(key.first), kMaxEndpoints);
    }
    return -1;
  }

  // Takes every report that arrived since the last call into the slots (through the delay stage, if there is one).
  void drain() {
    const std::int64_t now_ns = steady_now_ns();
    for (;;) {
      const dds_return_t taken = dds_take(report_reader, buffers.data(), infos.data(), kTakeBatch, kTakeBatch);
      if (taken <= 0) break;
      for (dds_return_t n = 0; n < taken; ++n) {
        const impetus_dds_HapticReport& sample = *samples[n];
        const Key key{sample.client_id, sample.client_endpoint};
        if (key.first == 0) continue;
        int slot = slot_of(key);
        if (infos[n].valid_data && sample.world_id != 0 && sample.world_id != world_id) {
          // A controller that follows another world on this partition: nothing of it is applied here, and a slot it
          // held before it chose is free again.
          ++foreign;
          if (slot >= 0) {
            std::fprintf(stderr, "world_manager: endpoint slot %d is free again (controller %016llx follows another "
                         "world on this partition)\n", slot, static_cast<unsigned long long>(key.first));
            slots[slot].key = Key{0, 0};
            ++released;
            publish_info();
          }
          continue;
        }
        if (infos[n].valid_data) {
          if (!from_dds(sample, report_wire) || decode(report_wire, report) != FrameError::ok ||
              report.endpoint != sample.client_endpoint) {
            ++rejected;
          } else {
            if (slot < 0) slot = take_slot(key);
            // A report of session 0 only asks for a slot: the controller's servo has not rendered anything yet.
            if (slot >= 0 && report.haptic_session != 0) {
              if (staged) {
                stages[static_cast<std::size_t>(slot)].push(now_ns, report);
              } else {
                slots[slot].latest = report;
                slots[slot].have = true;
              }
            }
          }
        }
        if (infos[n].instance_state != DDS_IST_ALIVE && slot >= 0) {
          // The controller left (disposed its key) or went silent past its lease: the slot is free again. The world
          // keeps its last report until a new holder's arrives, and drops the finger as stale meanwhile.
          std::fprintf(stderr, "world_manager: endpoint slot %d is free again (controller %016llx left or stopped "
                       "answering)\n", slot, static_cast<unsigned long long>(key.first));
          slots[slot].key = Key{0, 0};
          ++released;
          publish_info();
        }
      }
    }
    if (!staged) return;
    for (std::uint32_t k = 0; k < kMaxEndpoints; ++k) {
      if (!stages[k].active()) continue;
      if (const HapticReport* due = stages[k].take_due(now_ns)) {
        slots[k].latest = *due;
        slots[k].have = true;
      }
    }
  }

  // The newest loop statistics of each controller, by client id, into the slots it holds.
  void take_stats() {
    impetus_dds_HapticStats sample{};
    void* buffer = &sample;
    dds_sample_info_t sample_info{};
    while (dds_take(stats_reader, &buffer, &sample_info, 1, 1) > 0) {
      if (!sample_info.valid_data) continue;
      for (Slot& slot : slots) {
        if (slot.key.first == sample.client_id) {
          from_dds(sample.stats, slot.stats);
          slot.have_stats = true;
        }
      }
    }
  }

  DdsParticipant participant;
  WorldLinkInfo info;
  std::uint64_t world_id;
  // The delay and loss stage on the reports (DdsLinkOptions::delay_s, loss), one per slot, sized when a slot is taken.
  std::int64_t delay_ns;
  LinkLoss loss;
  bool staged;
  std::array<DelayStage<HapticReport>, kMaxEndpoints> stages;
  dds_entity_t frame_writer = 0;
  dds_entity_t report_reader = 0;
  dds_entity_t info_writer = 0;
  dds_entity_t stats_reader = 0;
  std::array<Slot, kMaxEndpoints> slots{};
  std::array<DdsReportSample, kTakeBatch> samples;
  std::array<void*, kTakeBatch> buffers{};
  std::array<dds_sample_info_t, kTakeBatch> infos{};
  DdsFrameSample frame_sample;
  wire::PlaneFrame frame_wire{};
  wire::HapticReport report_wire{};
  HapticReport report{};
  std::set<Key> refused_keys;
  std::uint64_t rejected = 0;
  std::uint64_t released = 0;
  std::uint64_t foreign = 0;  // reports for another world on the partition
};

DdsWorldLinkServer::DdsWorldLinkServer(const DdsLinkOptions& options, const WorldLinkInfo& info) {
  if (info.clock != ClockMode::realtime) {
    throw std::invalid_argument("the DDS world link runs in real time only (--clock realtime); lockstep trials use "
                                "shared memory or the in-process loop");
  }
  state_ = std::make_unique<State>(options, info);
}

DdsWorldLinkServer::~DdsWorldLinkServer() = default;

bool DdsWorldLinkServer::latest_report(std::uint32_t slot, HapticReport& out) {
  state_->drain();
  if (slot >= kMaxEndpoints || !state_->slots[slot].have) return false;
  out = state_->slots[slot].latest;
  return true;
}

void DdsWorldLinkServer::publish_frame(std::uint32_t slot, const PlaneFrame& frame) {
  if (slot >= kMaxEndpoints) return;
  State& state = *state_;
  const Key key = state.slots[slot].key;
  if (key.first == 0) return;  // nobody holds the slot
  encode(frame, state.frame_wire);
  to_dds(state.frame_wire, key.first, key.second, state.world_id, *state.frame_sample);
  // A frame that cannot be sent is replaced by the next step's: the loss is the link's, and frames are best effort.
  dds_write(state.frame_writer, &*state.frame_sample);
}

bool DdsWorldLinkServer::latest_haptic_stats(std::uint32_t slot, LoopStats& out) {
  if (slot >= kMaxEndpoints) return false;
  state_->take_stats();
  if (!state_->slots[slot].have_stats) return false;
  out = state_->slots[slot].stats;
  return true;
}

std::uint64_t DdsWorldLinkServer::rejected_reports() const { return state_->rejected; }
std::uint64_t DdsWorldLinkServer::refused_endpoints() const { return state_->refused_keys.size(); }
std::uint64_t DdsWorldLinkServer::released_slots() const { return state_->released; }
std::uint64_t DdsWorldLinkServer::foreign_reports() const { return state_->foreign; }
std::string DdsWorldLinkServer::name() const { return describe(state_->participant.options()); }

// ---------------------------------------------------------------------------------------------------------------
// A haptic controller's end.

struct DdsWorldLinkClient::State {
  State(const DdsLinkOptions& options, std::uint32_t endpoint_count)
      : participant(options),
        endpoints(endpoint_count),
        client_id(new_session_id()),
        staged(options.delay_s > 0.0 || options.loss.rate > 0.0) {
    const auto delay_ns = static_cast<std::int64_t>(options.delay_s * 1e9);
    for (std::uint32_t k = 0; staged && k < endpoints; ++k) {
      stages[k].reset(delay_ns, stage_capacity(delay_ns, kStagedFrameRate_Hz), options.loss, 2 * k);
    }
    const dds_entity_t publisher = make_publisher(participant.handle(), options.partition);
    const dds_entity_t subscriber = make_subscriber(participant.handle(), options.partition);
    frame_reader = make_reader(
        subscriber, make_topic(participant.handle(), &impetus_dds_PlaneFrame_desc, kFrameTopic), Delivery::best_effort);
    report_writer = make_writer(
        publisher, make_topic(participant.handle(), &impetus_dds_HapticReport_desc, kReportTopic), Delivery::reliable);
    info_reader = make_reader(subscriber, make_topic(participant.handle(), &impetus_dds_WorldInfo_desc, kInfoTopic),
                              Delivery::reliable_durable);
    stats_writer = make_writer(
        publisher, make_topic(participant.handle(), &impetus_dds_HapticStats_desc, kStatsTopic), Delivery::best_effort);
    waitset = dds_check(dds_create_waitset(participant.handle()), "cannot create a DDS waitset");
    wake = dds_check(dds_create_guardcondition(participant.handle()), "cannot create a DDS guard condition");
    dds_check(dds_set_status_mask(frame_reader, DDS_DATA_AVAILABLE_STATUS), "DDS status mask");
    dds_check(dds_set_status_mask(info_reader, DDS_DATA_AVAILABLE_STATUS), "DDS status mask");
    dds_check(dds_waitset_attach(waitset, frame_reader, frame_reader), "DDS waitset");
    dds_check(dds_waitset_attach(waitset, info_reader, info_reader), "DDS waitset");
    dds_check(dds_waitset_attach(waitset, wake, wake), "DDS waitset");
    for (std::uint32_t k = 0; k < kTakeBatch; ++k) frame_buffers[k] = &*frame_samples[k];
    // Until its servo reports, each endpoint's newest report is one of session 0: it asks the world for a slot.
    for (std::uint32_t k = 0; k < endpoints; ++k) {
      HapticReport hello{};
      hello.endpoint = k;
      encode(hello, report_wire);
      reports[k].write(report_wire, used_bytes(report_wire));
    }
  }

  // Stops the threads before anything they use goes (also when the constructor that started them throws).
  ~State() {
    stop.store(true);
    dds_set_guardcondition(wake, true);
    if (receiver.joinable()) receiver.join();
    if (sender.joinable()) sender.join();
  }

  // Receiver thread: frames for this client into the endpoints' channels, and the world's info.
  void receive() {
    while (!stop.load()) {
      dds_duration_t wait = kReceiveWait;
      if (staged) {  // wake for the next frame the delay stage releases
        std::int64_t next_ns = std::numeric_limits<std::int64_t>::max();
        for (std::uint32_t k = 0; k < endpoints; ++k) next_ns = std::min(next_ns, stages[k].next_due_ns());
        if (next_ns != std::numeric_limits<std::int64_t>::max()) {
          wait = std::clamp<dds_duration_t>(next_ns - steady_now_ns(), 0, kReceiveWait);
        }
      }
      dds_waitset_wait(waitset, nullptr, 0, wait);
      take_frames();
      take_info();
      if (staged) release_frames();
    }
  }

  // Frames the delay stage holds that are due now go to the endpoints' channels.
  void release_frames() {
    const std::int64_t now_ns = steady_now_ns();
    for (std::uint32_t k = 0; k < endpoints; ++k) {
      if (const wire::PlaneFrame* due = stages[k].take_due(now_ns)) frames[k].write(*due, used_bytes(*due));
    }
  }

  void take_frames() {
    for (;;) {
      const dds_return_t taken =
          dds_take(frame_reader, frame_buffers.data(), frame_infos.data(), kTakeBatch, kTakeBatch);
      if (taken <= 0) return;
      for (dds_return_t n = 0; n < taken; ++n) {
        const impetus_dds_PlaneFrame& sample = *frame_samples[n];
        if (!frame_infos[n].valid_data || sample.client_id != client_id || sample.client_endpoint >= endpoints) {
          continue;
        }
        if (sample.world_id != followed.load()) {  // another world's, on the same partition
          foreign_frames.fetch_add(1);
          continue;
        }
        // decode() on the servo's side checks the seal and the content; a sample whose counts disagree with its
        // sequences cannot even be laid out, and is counted here.
        if (!from_dds(sample, received_wire)) {
          malformed_frames.fetch_add(1);
          continue;
        }
        if (staged) {
          stages[sample.client_endpoint].push(steady_now_ns(), received_wire);
        } else {
          frames[sample.client_endpoint].write(received_wire, used_bytes(received_wire));
        }
      }
    }
  }

  void take_info() {
    impetus_dds_WorldInfo sample{};
    void* buffer = &sample;
    dds_sample_info_t sample_info{};
    while (dds_take(info_reader, &buffer, &sample_info, 1, 1) > 0) {
      const std::lock_guard<std::mutex> lock(info_mutex);
      const bool live = sample_info.valid_data && sample_info.instance_state == DDS_IST_ALIVE;
      if (live && (world_id == 0 || sample.world_id == world_id || !alive.load())) {
        follow(sample);
      } else if (live) {
        // A second live world on the partition: it is refused, not adopted (this controller's impulse must land in
        // one world), and kept in mind in case the followed one goes.
        if (others.emplace(sample.world_id, sample).second) {
          other_worlds.fetch_add(1);
          std::fprintf(stderr, "haptic_controller: another world manager (world %016llx) is live on %s; this "
                       "controller serves world %016llx only and ignores it\n",
                       static_cast<unsigned long long>(sample.world_id), describe(participant.options()).c_str(),
                       static_cast<unsigned long long>(world_id));
        } else {
          others[sample.world_id] = sample;
        }
      } else if (sample.world_id == world_id) {
        alive.store(false);  // the world left, or its process stopped answering
        if (!others.empty()) {
          // Another world is live on the partition: it takes the place of the one that went.
          const impetus_dds_WorldInfo next = others.begin()->second;
          others.erase(others.begin());
          follow(next);
        }
      } else {
        others.erase(sample.world_id);
      }
    }
  }

  // Follows the world of `sample` (the first, the same one again, or one that took a dead world's place), and reads
  // how many of this controller's endpoints it serves. Holds info_mutex.
  void follow(const impetus_dds_WorldInfo& sample) {
    if (sample.world_id != world_id) {
      // The schedule is the first world's: the servo reads it without a lock, so it never changes under it (a
      // restarted world runs the same command line).
      const bool first = world_id == 0;
      if (!first) switched.store(true);
      world_id = sample.world_id;
      followed.store(world_id);
      others.erase(world_id);
      attaches.fetch_add(1);
      if (first) {
        info.world_rate_hz = sample.world_rate_hz;
        info.world_period_s = sample.world_period_s;
        info.phase_ticks = sample.phase_ticks;
        info.clock = static_cast<ClockMode>(sample.clock);
        info.coupling = static_cast<Coupling>(sample.coupling);
      }
    }
    served = 0;
    free_slots = 0;
    for (const impetus_dds_SlotHolder& holder : sample.slots) {
      if (holder.client_id == client_id) ++served;
      if (holder.client_id == 0) ++free_slots;
    }
    alive.store(true);
  }

  // Sender thread: each endpoint's newest report, once per period. When the controller stops, the reports its servo
  // wrote after the last period go out too, and the world has up to kFinalAckWait to acknowledge them: the running
  // totals it applies last are then the controller's last.
  void send() {
    std::array<std::uint64_t, kMaxEndpoints> last_sequence{};
    std::array<std::chrono::steady_clock::time_point, kMaxEndpoints> last_sent{};
    std::uint64_t stats_sequence = 0;
    auto next = std::chrono::steady_clock::now();
    const auto send_reports = [&](std::chrono::steady_clock::time_point now) {
      for (std::uint32_t k = 0; k < endpoints; ++k) {
        const bool fresh = reports[k].try_read(sent_wire[k], last_sequence[k]);
        const bool repeat = std::chrono::duration<double>(now - last_sent[k]).count() > kReportRepeat_s;
        if (!fresh && !repeat) continue;
        to_dds(sent_wire[k], client_id, k, followed.load(), *send_sample);
        if (dds_write(report_writer, &*send_sample) >= 0) sent.fetch_add(1);
        last_sent[k] = now;
      }
    };
    while (!stop.load()) {
      next += kSendPeriod;
      std::this_thread::sleep_until(next);
      const auto now = std::chrono::steady_clock::now();
      if (now - next > 100 * kSendPeriod) next = now;  // after a long stall, do not try to catch up
      send_reports(now);
      if (stats.try_read(sent_stats.stats_local, stats_sequence)) {
        sent_stats.sample.client_id = client_id;
        to_dds(sent_stats.stats_local, sent_stats.sample.stats);
        dds_write(stats_writer, &sent_stats.sample);
      }
    }
    send_reports(std::chrono::steady_clock::now());
    if (alive.load()) dds_wait_for_acks(report_writer, kFinalAckWait);
  }

  DdsParticipant participant;
  std::uint32_t endpoints;
  std::uint64_t client_id;
  dds_entity_t frame_reader = 0;
  dds_entity_t report_writer = 0;
  dds_entity_t info_reader = 0;
  dds_entity_t stats_writer = 0;
  dds_entity_t waitset = 0;
  dds_entity_t wake = 0;

  // World → servo and servo → world, one channel per endpoint (~30 KB and ~8 KB each: on the heap with the state).
  std::array<SeqlockChannel<wire::PlaneFrame>, kMaxEndpoints> frames;
  std::array<SeqlockChannel<wire::HapticReport>, kMaxEndpoints> reports;
  // The delay and loss stage on the frames (DdsLinkOptions::delay_s, loss), one per endpoint; the receiver's alone.
  bool staged;
  std::array<DelayStage<wire::PlaneFrame>, kMaxEndpoints> stages;
  SeqlockChannel<LoopStats> stats;  // the controller's loop statistics, now and then

  // Servo thread.
  wire::PlaneFrame frame_wire{};
  wire::HapticReport report_wire{};
  std::array<std::uint64_t, kMaxEndpoints> last_frame_sequence{};
  std::uint64_t rejected = 0;

  // Receiver thread.
  std::array<DdsFrameSample, kTakeBatch> frame_samples;
  std::array<void*, kTakeBatch> frame_buffers{};
  std::array<dds_sample_info_t, kTakeBatch> frame_infos{};
  wire::PlaneFrame received_wire{};
  std::atomic<std::uint64_t> malformed_frames{0};

  // Sender thread.
  std::array<wire::HapticReport, kMaxEndpoints> sent_wire{};
  DdsReportSample send_sample;
  struct {
    LoopStats stats_local{};
    impetus_dds_HapticStats sample{};
  } sent_stats;
  std::atomic<std::uint64_t> sent{0};

  // The world's info (written by the receiver; info is read by the constructor before the servo starts).
  std::mutex info_mutex;
  WorldLinkInfo info{};
  std::uint64_t world_id = 0;
  std::uint32_t served = 0;
  std::uint32_t free_slots = 0;
  std::atomic<bool> alive{false};
  std::atomic<bool> switched{false};
  std::atomic<std::uint64_t> attaches{0};
  std::atomic<std::uint64_t> followed{0};         // world_id, for the sender's reports and the receiver's frames
  std::map<std::uint64_t, impetus_dds_WorldInfo> others;  // other live worlds on the partition, newest info each
  std::atomic<std::uint64_t> other_worlds{0};     // how many were seen
  std::atomic<std::uint64_t> foreign_frames{0};   // frames from them, dropped

  std::atomic<bool> stop{false};
  std::thread receiver;
  std::thread sender;
};

DdsWorldLinkClient::DdsWorldLinkClient(const DdsLinkOptions& options, ClockMode clock, double wait_s,
                                       std::uint32_t endpoints) {
  if (clock != ClockMode::realtime) {
    throw std::invalid_argument("the DDS world link runs in real time only (--clock realtime); lockstep trials use "
                                "shared memory or the in-process loop");
  }
  if (endpoints == 0 || endpoints > kMaxEndpoints) {
    throw std::invalid_argument("a haptic controller serves 1 to " + std::to_string(kMaxEndpoints) +
                                " endpoints, not " + std::to_string(endpoints));
  }
  state_ = std::make_unique<State>(options, endpoints);
  State& state = *state_;
  state.receiver = std::thread([&state] { state.receive(); });
  state.sender = std::thread([&state] { state.send(); });
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  for (;;) {
    std::uint64_t world = 0;
    std::uint32_t served = 0;
    std::uint32_t free_slots = 0;
    {
      const std::lock_guard<std::mutex> lock(state.info_mutex);
      world = state.world_id;
      served = state.served;
      free_slots = state.free_slots;
    }
    if (world != 0 && served >= endpoints) break;
    if (std::chrono::steady_clock::now() > give_up || g_stop_requested.load()) {
      const std::string where = describe(options);
      if (world == 0) {
        throw std::runtime_error(
            "no world manager answered on " + where + " within " + readable(wait_s) +
            " s (is it running with --link dds and the same --dds-domain and --dds-partition" +
            (options.security_dir.empty()
                 ? std::string(", and is it open? a secured world answers only secured participants)")
                 : std::string(", and secured with credentials of the same CAs? scripts/dds_security.sh)")));
      }
      throw std::runtime_error("the world on " + where + " gave this controller " + std::to_string(served) + " of " +
                               std::to_string(endpoints) + " endpoint slot(s) within " + std::to_string(wait_s) +
                               " s; it has " + std::to_string(free_slots) + " free of " +
                               std::to_string(kMaxEndpoints));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Attaching to the first world is not a re-attachment.
  state.switched.store(false);
}

DdsWorldLinkClient::~DdsWorldLinkClient() = default;

const WorldLinkInfo& DdsWorldLinkClient::info() const { return state_->info; }
std::uint32_t DdsWorldLinkClient::endpoints() const { return state_->endpoints; }

bool DdsWorldLinkClient::receive_frame(EndpointId endpoint, PlaneFrame& out) {
  State& state = *state_;
  if (endpoint >= state.endpoints) return false;
  std::size_t copied = 0;
  if (!state.frames[endpoint].try_read(state.frame_wire, state.last_frame_sequence[endpoint], 4, &copied)) {
    return false;
  }
  if (used_bytes(state.frame_wire) > copied || decode(state.frame_wire, out) != FrameError::ok) {
    ++state.rejected;
    return false;
  }
  return true;
}

void DdsWorldLinkClient::publish_stats(const LoopStats& stats) { state_->stats.write(stats); }

void DdsWorldLinkClient::publish_report(const HapticReport& report) {
  State& state = *state_;
  if (report.endpoint >= state.endpoints) return;
  encode(report, state.report_wire);
  state.reports[report.endpoint].write(state.report_wire, used_bytes(state.report_wire));
}

bool DdsWorldLinkClient::world_alive() const { return state_->alive.load(); }
bool DdsWorldLinkClient::reattach() {
  const bool switched = state_->switched.exchange(false);
  if (switched) std::fprintf(stderr, "haptic_controller: a new world manager answered on the DDS link\n");
  return switched;
}
std::uint64_t DdsWorldLinkClient::rejected_frames() const {
  return state_->rejected + state_->malformed_frames.load();
}
std::uint64_t DdsWorldLinkClient::attaches() const { return state_->attaches.load(); }
std::uint64_t DdsWorldLinkClient::client_id() const { return state_->client_id; }
std::uint64_t DdsWorldLinkClient::reports_sent() const { return state_->sent.load(); }
std::uint64_t DdsWorldLinkClient::other_worlds() const { return state_->other_worlds.load(); }
std::uint64_t DdsWorldLinkClient::foreign_frames() const { return state_->foreign_frames.load(); }

}  // namespace impetus
