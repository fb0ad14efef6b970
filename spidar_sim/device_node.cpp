// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/device_node.h"

#include "common/runtime/lockstep.h"
#include "common/runtime/process.h"
#include "common/runtime/realtime_clock.h"
#include "spidar_sim/grip_device_sim.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace impetus {
namespace {

// The device's own servo rate in real time; the finger sub-steps inside each tick (device_sim.h).
constexpr double kDevicePeriod_s = 1e-3;
// Statistics and (real time) the host's liveness, which reads /proc: every 100 ticks, ten times a second.
constexpr std::uint64_t kCheckEveryTicks = 100;
// Rows of the log ring: 2 s at 1 kHz, far more than the log thread's 2 ms sleep needs.
constexpr std::size_t kLogRows = 2048;

}  // namespace

template <class Sim>
DeviceNodeOf<Sim>::DeviceNodeOf(Sim& sim, DevicePortClient& port, const std::string& log_path,
                                std::uint64_t device_session)
    : sim_(sim), port_(port), session_(device_session) {
  if (!log_path.empty()) {
    log_.emplace(log_path, Sim::log_header(), Sim::format_log_row, kLogRows,
                 port.clock() == ClockMode::lockstep ? LogOverflow::wait : LogOverflow::drop, "spidar_sim");
  }
}

template <class Sim>
void DeviceNodeOf<Sim>::tick(double dt_s) {
  // Minimum tensions until a command arrives, and while the last one is stale (command_watchdog.h): what a haptic
  // side that sends nothing means (the strings stay taut).
  std::array<double, Sim::kStrings> tensions{};
  tensions.fill(sim_.tension_min_N());
  DeviceCommand command;
  const bool received = port_.latest_command(command);
  if (received && (command.flags & kCommandWorldPresent) != 0) world_seen_ = true;
  if (holding_for_world_) {
    if (world_seen_ || held_s_ >= world_wait_s_) {
      holding_for_world_ = false;
    } else {
      sim_.hold_trajectory(dt_s);
      held_s_ += dt_s;
    }
  }
  if (watchdog_.applies(received ? &command : nullptr, sim_.time_s())) {
    tensions = first_strings<Sim::kStrings>(command.tension_N);
  }
  DeviceState state = sim_.tick(tensions, dt_s);
  state.device_session = session_;
  port_.publish_state(state);
  if (log_) log_->push(sim_.log_row());
  ++ticks_;
}

template <class Sim>
bool DeviceNodeOf<Sim>::step_device() {
  if (sim_.finished()) {
    // The last turn carries no new state: the host sees the detach and frees the slot.
    port_.detach();
    return false;
  }
  tick(port_.haptic_period_s());
  if (ticks_ % kCheckEveryTicks == 0) {
    publish_stats(nullptr);
  }
  return true;
}

template <class Sim>
void DeviceNodeOf<Sim>::publish_stats(const RealtimeClock* clock) {
  LoopStats stats = loop_stats_now(clock);
  stats.ticks = ticks_;
  stats.rejected_frames = port_.rejected_commands();
  port_.publish_stats(stats);
}

template <class Sim>
int DeviceNodeOf<Sim>::run() {
  if (port_.clock() == ClockMode::lockstep) {
    // While the haptic controller has the turn, this thread writes the log's rows.
    const LockstepIdleWork idle(
        [](void* node) {
          auto& log = static_cast<DeviceNodeOf*>(node)->log_;
          return log && log->drain_one();
        },
        this);
    for (;;) {
      const TurnResult result = port_.wait_turn();
      if (result == TurnResult::shutdown) {
        std::fprintf(stderr, "spidar_sim: the haptic controller ended the session\n");
        break;
      }
      if (result != TurnResult::ok) {
        if (result == TurnResult::corrupted) {
          std::fprintf(stderr, "spidar_sim: error: %s; the trial is incomplete\n", to_string(result));
          cut_short_ = true;
        } else if (g_stop_requested.load()) {
          std::fprintf(stderr, "spidar_sim: stopped\n");
        } else {
          std::fprintf(stderr, "spidar_sim: error: the haptic controller went away mid-trajectory (lockstep); the "
                               "trial is incomplete\n");
          cut_short_ = true;
        }
        break;
      }
      const bool ticked = step_device();
      // Turns keep coming while the master runs, so a stop is taken between them: this turn becomes the last, handed
      // back as a detach so the host frees the slot instead of finding a dead device.
      const bool stopping = ticked && g_stop_requested.load();
      if (stopping) port_.detach();
      port_.finish_turn();
      if (!ticked) break;
      if (stopping) {
        std::fprintf(stderr, "spidar_sim: stopped\n");
        break;
      }
    }
    publish_stats(nullptr);
  } else {
    RealtimeClock clock(kDevicePeriod_s);
    bool host_alive = true;
    holding_for_world_ = world_wait_s_ > 0.0;
    if (holding_for_world_) {
      std::fprintf(stderr, "spidar_sim: holding the trajectory at its start until the haptic controller renders a "
                           "world (at most %.3g s)\n", world_wait_s_);
    }
    while (!g_stop_requested.load() && !sim_.finished() && host_alive) {
      const TickTiming timing = clock.wait_next();
      if (timing.index % kCheckEveryTicks == 0) host_alive = port_.host_alive();
      const bool was_holding = holding_for_world_;
      // After a host stall the finger is advanced by the real elapsed time, capped so one tick stays a tick.
      tick(std::min(timing.elapsed_s, Sim::kMaxTick_s));
      if (was_holding && !holding_for_world_) {
        if (world_seen_) {
          std::fprintf(stderr, "spidar_sim: the haptic controller renders a world; playing the trajectory (held "
                               "%.3f s)\n", held_s_);
        } else {
          std::fprintf(stderr, "spidar_sim: warning: no world reached the haptic controller within %.3g s; playing "
                               "the trajectory anyway\n", world_wait_s_);
        }
      }
      if (timing.index % kCheckEveryTicks == 0) publish_stats(&clock);
    }
    publish_stats(&clock);
    port_.detach();
  }
  if (log_) log_->close();
  // A failed log write was reported when the log's thread met it (rt_log.h).
  return cut_short_ || (log_ && log_->failed()) ? 1 : 0;
}

template <class Sim>
nlohmann::json DeviceNodeOf<Sim>::summary() const {
  nlohmann::json device = {{"ticks", ticks_},
                           {"time_s", sim_.time_s()},
                           {"rejected_commands", port_.rejected_commands()},
                           {"stale_command_ticks", watchdog_.stale_ticks()},
                           {"held_for_world_s", held_s_},
                           {"world_seen", world_seen_},
                           {"channel_repairs", port_.channel_repairs()}};
  device.update(sim_.summary_fields());
  return {{"device", device}};
}

template class DeviceNodeOf<DeviceSim>;
template class DeviceNodeOf<GripDeviceSim>;

nlohmann::json fingers_summary(std::span<const std::unique_ptr<DeviceNode>> nodes,
                               std::span<const NamedFinger> fingers) {
  nlohmann::json summary = nodes[0]->summary();
  if (nodes.size() < 2) return summary;  // a one-finger summary stays as it always was
  nlohmann::json per_finger = nlohmann::json::array();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    nlohmann::json one = nodes[k]->summary()["device"];
    one["name"] = fingers[k].name;
    one["trajectory"] = fingers[k].trajectory.description();
    per_finger.push_back(one);
  }
  summary["device"]["fingers"] = per_finger;
  return summary;
}

}  // namespace impetus
