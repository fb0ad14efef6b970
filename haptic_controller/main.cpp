// haptic_controller: the 1 kHz servo (DESIGN.md §1 "One haptic tick"). Creates the device port, opens the world link,
// and runs HapticServo on the real-time clock or as the lockstep master.

#include "common/csv_line.h"
#include "common/daemon.h"
#include "common/device_port.h"
#include "common/link_names.h"
#include "common/realtime_clock.h"
#include "common/rt_log.h"
#include "common/world_link.h"
#include "haptic_controller/servo.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <random>
#include <thread>
#include <vector>

namespace impetus {
namespace {

struct Options {
  double rate_hz = 1000.0;
  double stiffness_Npm = std::numeric_limits<double>::quiet_NaN();
  double damping_Nspm = std::numeric_limits<double>::quiet_NaN();
  ClockMode clock = ClockMode::realtime;
  double duration_s = 0.0;  // 0: until stopped
  std::string log_path;
  std::string summary_path;
  std::string shm = "impetus";
  double world_wait_s = 10.0;
  bool realtime_priority = true;
};

// A device whose state has not advanced for this long is stale (real time): the driver commands minimum tension.
// 50 ms is several host stalls' worth of slack for the device's own 1 kHz loop, and short enough that a dead device
// does not leave the strings pulling for a perceptible time.
constexpr double kDeviceStale_s = 0.05;
// Longest a lockstep follower may take for one turn before we call it stuck (a world step of a big scene takes
// milliseconds; this is a hang detector, not a deadline).
constexpr double kTurnTimeout_s = 60.0;
// Rows of the log ring: 2 s at 1 kHz, far more than the drain thread's 2 ms sleep needs.
constexpr std::size_t kLogRows = 2048;

struct HapticLogRow {
  std::uint64_t tick;
  double time_s;
  Vec3 finger_m, proxy_m, force_N;
  Vec3 object_impulse_Ns;  // sum of the cumulative totals over all objects
  Vec3 static_impulse_Ns;  // cumulative share into static geometry
  double interpolation_weight;
  std::int64_t lateness_ns;
  std::int32_t active_planes;
  std::uint32_t flags;  // bit 0 finger valid, 1 saturated, 2 fault, 3 world stale, 4 sticking
};

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

std::uint64_t make_session() {
  std::random_device entropy;
  const std::uint64_t session = (static_cast<std::uint64_t>(entropy()) << 32) ^ entropy() ^
                                static_cast<std::uint64_t>(getpid()) ^ static_cast<std::uint64_t>(monotonic_now_ns());
  return session == 0 ? 1 : session;
}

bool process_alive(std::int32_t pid) { return pid > 0 && kill(pid, 0) == 0; }

class HapticDaemon {
 public:
  explicit HapticDaemon(const Options& options)
      : options_(options),
        period_s_(1.0 / options.rate_hz),
        servo_(servo_options(options), make_session()),
        port_(Segment<DevicePortLayout>::create(device_port_name(options.shm), [&](DevicePortLayout& port) {
          port.clock = options.clock;
          port.haptic_period_s = 1.0 / options.rate_hz;
        })) {
    if (!options.log_path.empty()) {
      log_.emplace(options.log_path, kLogHeader, format_row, kLogRows,
                   options.clock == ClockMode::lockstep ? LogOverflow::wait : LogOverflow::drop);
    }
    worlds_.push_back(std::make_unique<Segment<WorldLinkLayout>>(
        open_when_ready<WorldLinkLayout>(world_link_name(options.shm), options.world_wait_s)));
    world_.store(&**worlds_.back(), std::memory_order_release);
    const WorldLinkConfig& config = world()->config;
    if (config.clock != options.clock) {
      throw std::runtime_error(std::string("the world manager runs --clock ") + to_string(config.clock) +
                               " but the haptic controller was started with --clock " + to_string(options.clock));
    }
    const double ticks_per_step = config.world_period_s * options.rate_hz;
    ticks_per_step_ = static_cast<std::uint64_t>(std::llround(ticks_per_step));
    if (options.clock == ClockMode::lockstep &&
        (ticks_per_step_ < 1 || std::fabs(ticks_per_step - static_cast<double>(ticks_per_step_)) > 1e-9)) {
      throw std::runtime_error("in lockstep the world period (" + std::to_string(config.world_period_s) +
                               " s) must be a whole number of haptic ticks");
    }
    world()->haptic_pid.store(static_cast<std::int32_t>(getpid()));
  }

  int run() {
    std::fprintf(stderr, "haptic_controller: %.0f Hz, %s clock, world at %.1f Hz, device port '%s'\n",
                 options_.rate_hz, to_string(options_.clock), world()->config.world_rate_hz, port_.name().c_str());
    if (options_.clock == ClockMode::lockstep) {
      run_lockstep();
    } else {
      run_realtime();
    }
    publish_stats(nullptr);
    if (log_) log_->close();
    write_summary();
    const ServoCounters& counters = servo_.counters();
    std::fprintf(stderr, "haptic_controller: %llu ticks, %llu faults, %llu force clamps, %llu saturations\n",
                 static_cast<unsigned long long>(counters.ticks), static_cast<unsigned long long>(counters.faults),
                 static_cast<unsigned long long>(counters.force_clamps),
                 static_cast<unsigned long long>(counters.saturations));
    return 0;
  }

 private:
  static ServoOptions servo_options(const Options& options) {
    ServoOptions servo;
    servo.stiffness_Npm = options.stiffness_Npm;
    servo.damping_Nspm = options.damping_Nspm;
    servo.tick_period_s = 1.0 / options.rate_hz;
    return servo;
  }

  WorldLinkLayout* world() const { return world_.load(std::memory_order_acquire); }

  // Not real-time (opens a segment, reads /proc): called from the supervisor thread in real time and between
  // turns in lockstep. If the world we follow has died and a new world manager has created the link again, switch
  // to it. Returns true if it switched.
  bool try_reattach_world() {
    if (worlds_.back()->creator_alive()) return false;
    try {
      auto fresh = std::make_unique<Segment<WorldLinkLayout>>(
          Segment<WorldLinkLayout>::open(world_link_name(options_.shm)));
      if (!fresh->creator_alive() || (*fresh)->config.clock != options_.clock) return false;
      (*fresh)->haptic_pid.store(static_cast<std::int32_t>(getpid()));
      worlds_.push_back(std::move(fresh));
      world_.store(&**worlds_.back(), std::memory_order_release);
      world_attaches_.fetch_add(1);
      std::fprintf(stderr, "haptic_controller: re-attached to a restarted world manager\n");
      return true;
    } catch (const SegmentError&) {
      return false;  // not (yet) there: the world keeps its last planes meanwhile
    }
  }

  std::uint64_t max_ticks() const {
    return options_.duration_s > 0.0 ? static_cast<std::uint64_t>(std::llround(options_.duration_s * options_.rate_hz))
                                     : std::numeric_limits<std::uint64_t>::max();
  }

  // Frees the device slot: the device detached or died. Its turn semaphores are re-initialised first, while no live
  // device can be waiting on them (the slot is still held), so stale posts cannot leak into the next attach.
  void release_device() {
    port_->device_turn.reset();
    port_->detaching.store(0, std::memory_order_release);
    port_->device_pid.store(0, std::memory_order_release);
    attached_pid_ = 0;
    last_device_sequence_ = 0;
    have_device_state_ = false;
  }

  // Lockstep: the device takes its turn for `tick`; returns its new state, or nullptr without a device.
  const DeviceState* device_turn_lockstep(std::uint64_t tick) {
    const std::int32_t pid = port_->device_pid.load(std::memory_order_acquire);
    if (pid == 0) return nullptr;
    attached_pid_ = pid;
    port_->device_turn.give(tick);
    const TurnResult result = port_->device_turn.wait_done([&] { return process_alive(pid); }, kTurnTimeout_s);
    if (result != TurnResult::ok || port_->detaching.load(std::memory_order_acquire) != 0) {
      release_device();
      return nullptr;
    }
    return read_device_state();
  }

  // Real time: the latest device state if it is fresh, else nullptr. Detach and death are noticed here too.
  const DeviceState* device_state_realtime(double now_s) {
    const std::int32_t pid = port_->device_pid.load(std::memory_order_acquire);
    if (pid == 0) return nullptr;
    if (pid != attached_pid_) {
      attached_pid_ = pid;
      device_fresh_s_ = now_s;  // a new device gets the full grace period for its first state
    }
    if (port_->detaching.load(std::memory_order_acquire) != 0) {
      release_device();
      return nullptr;
    }
    if (read_device_state()) device_fresh_s_ = now_s;
    if (now_s - device_fresh_s_ > kDeviceStale_s || !have_device_state_) {
      // A stale device gets minimum tension; a dead one (kill(pid, 0) is a cheap syscall, not I/O) also loses its
      // slot so that a new device can attach.
      if (!process_alive(pid)) release_device();
      return nullptr;
    }
    return &device_state_;
  }

  // Reads a new device state into device_state_ (validated); returns it, or nullptr if none arrived.
  const DeviceState* read_device_state() {
    DeviceState state;
    if (!port_->state.try_read(state, last_device_sequence_)) return nullptr;
    if (validate(state) != FrameError::ok) {
      ++rejected_frames_;
      return nullptr;
    }
    device_state_ = state;
    have_device_state_ = true;
    return &device_state_;
  }

  void read_world_frame(double now_s) {
    PlaneFrame& frame = frame_buffer_;
    WorldLinkLayout* current = world();
    if (current != frames_from_) {  // re-attached to a restarted world: its sequence numbers start afresh
      frames_from_ = current;
      last_frame_sequence_ = 0;
    }
    if (!current->planes.try_read(frame, last_frame_sequence_)) return;
    if (validate(frame) != FrameError::ok) {
      ++rejected_frames_;
      return;
    }
    servo_.on_plane_frame(frame, now_s);
  }

  // Everything after the device reading: the servo tick, the command to the device, the report to the world, the log.
  void servo_tick(const DeviceState* device, std::uint64_t tick, double now_s, double dt_s, std::int64_t lateness_ns) {
    const std::int64_t cpu_before_ns = thread_cpu_now_ns();
    const TickResult& result = servo_.tick(device, now_s, dt_s);
    tick_cpu_ns_.record(thread_cpu_now_ns() - cpu_before_ns);
    DeviceCommand command;
    command.tick = tick;
    command.haptic_session = servo_.report().haptic_session;
    command.tension_N = result.tension_N;
    seal(command);
    port_->command.write(command);

    report_ = servo_.report();
    seal(report_);
    world()->report.write(report_);

    if (log_) {
      HapticLogRow row{};
      row.tick = tick;
      row.time_s = now_s;
      row.finger_m = result.finger_m;
      row.proxy_m = result.proxy_m;
      row.force_N = result.force_N;
      for (std::uint32_t k = 0; k < report_.entry_count; ++k) {
        for (int a = 0; a < 3; ++a) row.object_impulse_Ns[a] += report_.entries[k].impulse_Ns[a];
      }
      row.static_impulse_Ns = report_.static_impulse_Ns;
      row.interpolation_weight = result.interpolation_weight;
      row.lateness_ns = lateness_ns;
      row.active_planes = result.active_planes;
      row.flags = (result.finger_valid ? 1u : 0u) | (result.saturated ? 2u : 0u) | (result.fault ? 4u : 0u) |
                  (result.world_stale ? 8u : 0u) | (result.sticking ? 16u : 0u);
      log_->push(row);
    }
    max_force_N_ = std::max(max_force_N_, std::sqrt(result.force_N[0] * result.force_N[0] +
                                                    result.force_N[1] * result.force_N[1] +
                                                    result.force_N[2] * result.force_N[2]));
  }

  // Lockstep time advances only while a device is attached: a lockstep run is in step with its device, so a session
  // starts from the same state whenever the device attaches, and nothing is simulated while nobody is there.
  bool wait_for_device() {
    while (port_->device_pid.load(std::memory_order_acquire) == 0) {
      if (g_stop_requested.load()) return false;
      usleep(1'000);
    }
    return true;
  }

  void run_lockstep() {
    const std::uint64_t phase = world()->config.phase_ticks;
    const std::uint64_t ticks = max_ticks();
    bool world_alive = true;
    for (std::uint64_t tick = 0; tick < ticks && wait_for_device(); ++tick) {
      // Exactly tick·T: interpolation weights are then tick counts over n, the same in every run.
      const double now_s = static_cast<double>(tick) * period_s_;
      const DeviceState* device = device_turn_lockstep(tick);
      servo_tick(device, tick, now_s, period_s_, 0);
      const bool world_step_due = tick >= phase && (tick - phase) % ticks_per_step_ == 0;
      if (world_step_due && !world_alive) world_alive = try_reattach_world();
      if (world_step_due && world_alive) {
        WorldLinkLayout& link = *world();
        link.world_turn.give(tick);
        const TurnResult result =
            link.world_turn.wait_done([&] { return worlds_.back()->creator_alive(); }, kTurnTimeout_s);
        if (result == TurnResult::ok) {
          read_world_frame(now_s);
        } else {
          std::fprintf(stderr, "haptic_controller: the world manager went away; keeping its last planes\n");
          world_alive = false;
        }
      }
      if (tick % 100 == 0) publish_stats(nullptr);
    }
    world()->world_turn.request_shutdown();
    port_->device_turn.request_shutdown();
  }

  void run_realtime() {
    if (options_.realtime_priority) {
      const std::string warning = request_realtime(80);
      if (!warning.empty()) std::fprintf(stderr, "haptic_controller: warning: %s\n", warning.c_str());
    }
    // The supervisor does what the servo loop must not: liveness checks through /proc and re-opening segments.
    std::atomic<bool> loop_done{false};
    std::thread supervisor([&] {
      while (!loop_done.load()) {
        try_reattach_world();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
    RealtimeClock clock(period_s_);
    const std::uint64_t ticks = max_ticks();
    while (!g_stop_requested.load() && clock.ticks() < ticks) {
      const TickTiming timing = clock.wait_next();
      const DeviceState* device = device_state_realtime(timing.now_s);
      read_world_frame(timing.now_s);
      servo_tick(device, timing.index, timing.now_s, timing.elapsed_s, timing.lateness_ns);
      if (timing.index % 100 == 0) publish_stats(&clock);
    }
    loop_done.store(true);
    supervisor.join();
    publish_stats(&clock);
    clock_stats_ = clock.lateness();
    skipped_periods_ = clock.skipped_periods();
  }

  void publish_stats(const RealtimeClock* clock) {
    LoopStats stats = loop_stats_now(clock);
    stats.ticks = servo_.counters().ticks;
    stats.faults = servo_.counters().faults;
    stats.rejected_frames = rejected_frames_;
    world()->haptic_stats.write(stats);
  }

  void write_summary() const {
    if (options_.summary_path.empty()) return;
    const ServoCounters& counters = servo_.counters();
    nlohmann::json impulses = nlohmann::json::object();
    const HapticReport& report = servo_.report();
    for (std::uint32_t k = 0; k < report.entry_count; ++k) {
      const ObjectImpulse& entry = report.entries[k];
      impulses[std::to_string(entry.object_id)] = {entry.impulse_Ns[0], entry.impulse_Ns[1], entry.impulse_Ns[2]};
    }
    const nlohmann::json summary = {
        {"haptic",
         {{"ticks", counters.ticks},
          {"rate_hz", options_.rate_hz},
          {"faults", counters.faults},
          {"force_clamps", counters.force_clamps},
          {"saturations", counters.saturations},
          {"infeasible_contacts", counters.infeasible_contacts},
          {"stale_world_ticks", counters.stale_world_ticks},
          {"no_device_ticks", counters.no_device_ticks},
          {"dropped_impulse_shares", counters.dropped_impulse_shares},
          {"contact_frame_boundaries", counters.contact_frame_boundaries},
          {"frame_jump_max_m", counters.frame_jump_max_m},
          {"local_model_error_max_m", counters.local_model_error_max_m},
          {"rejected_frames", rejected_frames_},
          {"world_attaches", world_attaches_.load()},
          {"log_rows_dropped", log_ ? log_->dropped() : 0},
          {"max_force_N", max_force_N_},
          {"skipped_periods", skipped_periods_},
          {"lateness_p50_ns", clock_stats_.percentile_ns(0.5)},
          {"lateness_p99_ns", clock_stats_.percentile_ns(0.99)},
          {"lateness_p999_ns", clock_stats_.percentile_ns(0.999)},
          {"lateness_max_ns", clock_stats_.max_ns()},
          {"cpu_per_tick_p50_ns", tick_cpu_ns_.percentile_ns(0.5)},
          {"cpu_per_tick_p99_ns", tick_cpu_ns_.percentile_ns(0.99)},
          {"cpu_per_tick_mean_ns", tick_cpu_ns_.mean_ns()},
          {"impulse_by_object_Ns", impulses},
          {"static_impulse_Ns", {report.static_impulse_Ns[0], report.static_impulse_Ns[1],
                                 report.static_impulse_Ns[2]}}}}};
    std::ofstream out(options_.summary_path);
    out << summary.dump(2) << '\n';
  }

  const Options& options_;
  double period_s_;
  HapticServo servo_;
  Segment<DevicePortLayout> port_;
  // Every world link we attached to, oldest first. A restarted world manager creates a new segment; the old mapping
  // stays alive here (never unmapped while the servo loop might still read it) and `world_` moves to the new one.
  std::vector<std::unique_ptr<Segment<WorldLinkLayout>>> worlds_;
  std::atomic<WorldLinkLayout*> world_{nullptr};
  WorldLinkLayout* frames_from_ = nullptr;
  std::atomic<std::uint64_t> world_attaches_{1};
  std::optional<RtLog<HapticLogRow>> log_;
  std::uint64_t ticks_per_step_ = 1;
  std::int32_t attached_pid_ = 0;
  std::uint64_t last_device_sequence_ = 0;
  std::uint64_t last_frame_sequence_ = 0;
  DeviceState device_state_{};
  bool have_device_state_ = false;
  double device_fresh_s_ = 0.0;
  PlaneFrame frame_buffer_{};
  HapticReport report_{};
  std::uint64_t rejected_frames_ = 0;
  double max_force_N_ = 0.0;
  LatencyHistogram clock_stats_;
  LatencyHistogram tick_cpu_ns_;  // CPU time of HapticServo::tick, per tick
  std::uint64_t skipped_periods_ = 0;
};

}  // namespace
}  // namespace impetus

int main(int argc, char** argv) {
  using namespace impetus;
  Options options;
  CLI::App app{"haptic_controller: the 1 kHz haptic servo of Impetus. Interpolates the world's planes, renders the "
               "god-object force on the SPIDAR and integrates it into impulses for the world."};
  app.add_option("--rate", options.rate_hz, "servo rate in Hz (1000)")->check(CLI::Range(100.0, 20000.0));
  app.add_option("--stiffness", options.stiffness_Npm, "k_p in N/m (default: the scene's)")
      ->check(CLI::PositiveNumber);
  app.add_option("--damping", options.damping_Nspm, "k_d in N·s/m (default: the scene's)")
      ->check(CLI::NonNegativeNumber);
  add_clock_flag(app, options.clock);
  app.add_option("--duration", options.duration_s, "seconds to run (default: until stopped)")
      ->check(CLI::PositiveNumber);
  add_output_flag(app, "--log", options.log_path,
                  "CSV log: finger, proxy, force, accumulated impulse, lateness per tick");
  add_output_flag(app, "--summary", options.summary_path, "JSON summary written at exit (loop statistics, faults)");
  add_shm_flag(app, options.shm);
  app.add_option("--world-wait", options.world_wait_s, "seconds to wait for the world manager's link (10)")
      ->check(CLI::PositiveNumber);
  app.add_flag("!--no-realtime-priority", options.realtime_priority,
               "do not ask for SCHED_FIFO and mlockall in real time");
  CLI11_PARSE(app, argc, argv);

  install_stop_handlers();
  try {
    HapticDaemon daemon(options);
    return daemon.run();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "haptic_controller: error: %s\n", error.what());
    return 1;
  }
}
