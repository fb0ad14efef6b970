// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/haptic_node.h"

#include "common/runtime/csv_line.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/process.h"
#include "common/runtime/realtime_clock.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

namespace impetus {
namespace {

// Rows of the log ring: 2 s at 1 kHz, far more than the drain thread's 2 ms sleep needs.
constexpr std::size_t kLogRows = 2048;
// Loop statistics are published every this many ticks (10 Hz at 1 kHz: a heartbeat, not a trace).
constexpr std::uint64_t kStatsEveryTicks = 100;

constexpr const char* kLogHeader =
    "time_s,tick,finger_x,finger_y,finger_z,proxy_x,proxy_y,proxy_z,force_x,force_y,force_z,"
    "object_impulse_x,object_impulse_y,object_impulse_z,static_impulse_x,static_impulse_y,static_impulse_z,"
    "weight,lateness_ns,active_planes,flags";

void format_row(std::ostream& out, const HapticLogRow& row) {
  CsvLine line(out);
  line.number(row.time_s).integer(static_cast<std::int64_t>(row.tick));
  line.numbers(row.finger_m).numbers(row.proxy_m).numbers(row.force_N);
  line.numbers(row.object_impulse_Ns).numbers(row.static_impulse_Ns);
  line.number(row.interpolation_weight).integer(row.lateness_ns).integer(row.active_planes).integer(row.flags);
}

ServoOptions servo_options(const HapticNodeOptions& options, const DeviceLimits& limits) {
  ServoOptions servo;
  servo.max_force_N = limits.max_force_N;
  servo.stiffness_Npm = options.stiffness_Npm;
  servo.damping_Nspm = options.damping_Nspm;
  servo.tick_period_s = 1.0 / options.rate_hz;
  return servo;
}

}  // namespace

HapticNode::HapticNode(const HapticNodeOptions& options, WorldLinkClient& world, HapticDevice& device)
    : options_(options),
      period_s_(1.0 / options.rate_hz),
      world_(world),
      device_(device),
      servo_(servo_options(options, device.limits()), options.haptic_session) {
  if (options.clock == ClockMode::lockstep) {
    LockstepSchedule::ticks_per_world_step(world.info().world_period_s, options.rate_hz);  // throws if not whole
  }
  if (!options.log_path.empty()) {
    log_.emplace(options.log_path, kLogHeader, format_row, kLogRows,
                 options.clock == ClockMode::lockstep ? LogOverflow::wait : LogOverflow::drop, "haptic_controller");
  }
}

std::uint64_t HapticNode::max_ticks() const {
  return options_.duration_s > 0.0 ? static_cast<std::uint64_t>(std::llround(options_.duration_s * options_.rate_hz))
                                   : std::numeric_limits<std::uint64_t>::max();
}

void HapticNode::receive_frame(double now_s) {
  if (world_.receive_frame(frame_buffer_)) servo_.on_plane_frame(frame_buffer_, now_s);
}

// After the world's frame: the finger, the servo tick, the force to the device, the report to the world, the log.
void HapticNode::tick(std::uint64_t tick, double now_s, double dt_s, std::int64_t lateness_ns) {
  const FingerSample* finger = device_.read(tick, now_s);
  // The servo's CPU time on every 64th tick: reading the thread's CPU clock is a system call (~1.4 µs here, more than
  // the tick it would measure), and a sample of 1 in 64 gives the same percentiles over any run of seconds.
  const bool sampled = (tick & 63u) == 0;
  const std::int64_t cpu_before_ns = sampled ? thread_cpu_now_ns() : 0;
  const TickResult& result = servo_.tick(finger, now_s, dt_s);
  if (sampled) tick_cpu_ns_.record(thread_cpu_now_ns() - cpu_before_ns);
  const bool saturated = !device_.command(tick, to_eigen(result.force_N), result.render);
  const HapticReport& report = servo_.report();
  world_.publish_report(report);

  if (log_) {
    HapticLogRow row{};
    row.tick = tick;
    row.time_s = now_s;
    row.finger_m = result.finger_m;
    row.proxy_m = result.proxy_m;
    row.force_N = result.force_N;
    for (std::uint32_t k = 0; k < report.entry_count; ++k) {
      for (int a = 0; a < 3; ++a) row.object_impulse_Ns[a] += report.entries[k].impulse_Ns[a];
    }
    row.static_impulse_Ns = report.static_impulse_Ns;
    row.interpolation_weight = result.interpolation_weight;
    row.lateness_ns = lateness_ns;
    row.active_planes = result.active_planes;
    row.flags = (result.finger_valid ? 1u : 0u) | (saturated ? 2u : 0u) | (result.fault ? 4u : 0u) |
                (result.world_stale ? 8u : 0u) | (result.sticking ? 16u : 0u);
    log_->push(row);
  }
  if (result.render) {
    stiffness_Npm_ = result.stiffness_Npm;
    damping_Nspm_ = result.damping_Nspm;
  }
  max_force_N_ = std::max(max_force_N_, std::sqrt(result.force_N[0] * result.force_N[0] +
                                                  result.force_N[1] * result.force_N[1] +
                                                  result.force_N[2] * result.force_N[2]));
}

// Lockstep time advances only while a device is attached: a lockstep run is in step with its device, so a session
// starts from the same state whenever the device attaches, and nothing is simulated while nobody is there.
void HapticNode::run_lockstep() {
  const LockstepSchedule schedule(LockstepSchedule::ticks_per_world_step(world_.info().world_period_s, options_.rate_hz),
                                  world_.info().phase_ticks);
  const std::uint64_t ticks = max_ticks();
  bool world_lost = false;
  // A stop request is checked every tick: the followers' turns keep coming, so the stop must come from the master.
  for (std::uint64_t t = 0; t < ticks && !g_stop_requested.load() && device_.wait_attached(); ++t) {
    // Exactly t·T: interpolation weights are then tick counts over n, the same in every run.
    const double now_s = static_cast<double>(t) * period_s_;
    tick(t, now_s, period_s_, 0);
    if (schedule.world_step_due(t)) {
      if (world_.step_world(t)) {
        receive_frame(now_s);
      } else {
        world_lost = true;
      }
    }
    if (t % kStatsEveryTicks == 0) publish_stats(nullptr);
  }
  // A world that died after its last step (between two steps, as the session ended) left the trial unfinished too.
  if (!world_lost && !world_.world_alive()) world_lost = true;
  world_.end_session();
  device_.end_session();
  // A lockstep trial is one deterministic run: a world or device that left mid-way makes it incomplete, whatever came
  // after (each loss was reported when it happened).
  if (world_lost || device_.counters().devices_lost > 0) {
    std::fprintf(stderr, "haptic_controller: error: the trial is incomplete: the %s went away mid-trial (lockstep)\n",
                 world_lost ? "world manager" : "device");
    cut_short_ = true;
  }
}

void HapticNode::run_realtime() {
  if (options_.realtime_priority) {
    const std::string warning = request_realtime(80);
    if (!warning.empty()) std::fprintf(stderr, "haptic_controller: warning: %s\n", warning.c_str());
  }
  std::atomic<bool> loop_done{false};
  std::thread supervisor([&] {
    while (!loop_done.load()) {
      world_.reattach();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  RealtimeClock clock(period_s_);
  const std::uint64_t ticks = max_ticks();
  while (!g_stop_requested.load() && clock.ticks() < ticks) {
    const TickTiming timing = clock.wait_next();
    receive_frame(timing.now_s);
    tick(timing.index, timing.now_s, timing.elapsed_s, timing.lateness_ns);
    if (timing.index % kStatsEveryTicks == 0) publish_stats(&clock);
  }
  // The device's minimum output as the servo stops: the last force commanded would otherwise stay on the finger.
  device_.command(clock.ticks(), Eigen::Vector3d::Zero(), false);
  loop_done.store(true);
  supervisor.join();
  publish_stats(&clock);
  clock_stats_ = clock.lateness();
  skipped_periods_ = clock.skipped_periods();
}

int HapticNode::run() {
  if (options_.clock == ClockMode::lockstep) {
    run_lockstep();
  } else {
    run_realtime();
  }
  publish_stats(nullptr);
  if (log_) log_->close();
  // A failed log write was reported when it happened (rt_log.h), a trial cut short at its end.
  return cut_short_ || (log_ && log_->failed()) ? 1 : 0;
}

void HapticNode::publish_stats(const RealtimeClock* clock) {
  LoopStats stats = loop_stats_now(clock);
  stats.ticks = servo_.counters().ticks;
  stats.faults = servo_.counters().faults;
  stats.rejected_frames = world_.rejected_frames() + device_.counters().rejected_frames;
  world_.publish_stats(stats);
}

nlohmann::json HapticNode::summary() const {
  const ServoCounters& counters = servo_.counters();
  nlohmann::json impulses = nlohmann::json::object();
  const HapticReport& report = servo_.report();
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    const ObjectImpulse& entry = report.entries[k];
    impulses[std::to_string(entry.object_id)] = {entry.impulse_Ns[0], entry.impulse_Ns[1], entry.impulse_Ns[2]};
  }
  return {{"haptic",
           {{"ticks", counters.ticks},
            {"rate_hz", options_.rate_hz},
            {"faults", counters.faults},
            {"force_clamps", counters.force_clamps},
            {"saturations", device_.counters().saturations},
            {"devices_lost", device_.counters().devices_lost},
            {"channel_repairs", world_.channel_repairs() + device_.counters().channel_repairs},
            {"infeasible_contacts", counters.infeasible_contacts},
            {"stale_world_ticks", counters.stale_world_ticks},
            {"no_device_ticks", counters.no_device_ticks},
            {"dropped_impulse_shares", counters.dropped_impulse_shares},
            {"abandoned_impulse_Ns",
             {servo_.accumulator().abandoned_impulse_Ns().x(), servo_.accumulator().abandoned_impulse_Ns().y(),
              servo_.accumulator().abandoned_impulse_Ns().z()}},
            {"contact_frame_boundaries", counters.contact_frame_boundaries},
            {"frame_jump_max_m", counters.frame_jump_max_m},
            {"local_model_error_max_m", counters.local_model_error_max_m},
            {"rejected_frames", world_.rejected_frames() + device_.counters().rejected_frames},
            {"world_attaches", world_.attaches()},
            {"log_rows_dropped", log_ ? log_->dropped() : 0},
            {"max_force_N", max_force_N_},
            {"force_limit_N", device_.limits().max_force_N},
            {"stiffness_Npm", stiffness_Npm_},
            {"damping_Nspm", damping_Nspm_},
            {"skipped_periods", skipped_periods_},
            {"lateness_p50_ns", clock_stats_.percentile_ns(0.5)},
            {"lateness_p99_ns", clock_stats_.percentile_ns(0.99)},
            {"lateness_p999_ns", clock_stats_.percentile_ns(0.999)},
            {"lateness_max_ns", clock_stats_.max_ns()},
            {"cpu_per_tick_p50_ns", tick_cpu_ns_.percentile_ns(0.5)},
            {"cpu_per_tick_p99_ns", tick_cpu_ns_.percentile_ns(0.99)},
            {"cpu_per_tick_mean_ns", tick_cpu_ns_.mean_ns()},
            {"cpu_per_tick_samples", tick_cpu_ns_.count()},  // every 64th tick
            {"impulse_by_object_Ns", impulses},
            {"static_impulse_Ns",
             {report.static_impulse_Ns[0], report.static_impulse_Ns[1], report.static_impulse_Ns[2]}}}}};
}

}  // namespace impetus
