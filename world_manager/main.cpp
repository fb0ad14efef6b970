// world_manager: the ODE world at the world rate (DESIGN.md §1 "One world step"). Creates the world link, steps the
// scene with the haptic controller's impulses (or the sampled finger, for position coupling) and publishes planes.

#include "common/daemon.h"
#include "common/device_geometry.h"
#include "common/link_names.h"
#include "common/realtime_clock.h"
#include "common/scene.h"
#include "common/world_link.h"
#include "world_manager/impulse_limits.h"
#include "world_manager/ode_runtime.h"
#include "world_manager/world.h"
#include "world_manager/world_log.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

namespace impetus {
namespace {

struct Options {
  std::string scene_path;
  std::optional<double> rate_hz;
  std::optional<int> substeps;
  Coupling coupling = Coupling::impulse;
  ClockMode clock = ClockMode::realtime;
  std::uint64_t phase_ticks = 0;
  double duration_s = 0.0;  // 0: until stopped
  std::string log_path;
  std::string summary_path;
  std::string shm = "impetus";
  double haptic_rate_hz = 1000.0;  // only to check that a lockstep world period is a whole number of haptic ticks
};

nlohmann::json to_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json summary_of(const World& world, const Options& options, const LoopStats& stats,
                          const LatencyHistogram& step_cpu_ns) {
  nlohmann::json objects = nlohmann::json::object();
  const auto states = world.states();
  for (std::size_t id = 0; id < world.scene().objects.size(); ++id) {
    const auto& object = world.scene().objects[id];
    if (!object.dynamic) continue;
    const ObjectState& state = states[id];
    const Eigen::Quaterniond& q = state.pose.orientation;
    objects[object.name] = {{"position", to_json(state.pose.position_m)},
                            {"orientation", {q.w(), q.x(), q.y(), q.z()}},
                            {"velocity", to_json(state.velocity_mps)},
                            {"angular_velocity", to_json(state.angular_velocity_radps)},
                            {"impulse_Ns", to_json(world.total_impulse_Ns(id))},
                            {"angular_impulse_Nms", to_json(world.total_angular_impulse_Nms(id))}};
  }
  return {{"objects", objects},
          {"world",
           {{"steps", world.steps_taken()},
            {"time_s", world.time_s()},
            {"period_s", world.world_period_s()},
            {"skipped_periods", stats.skipped_periods},
            {"rejected_reports", stats.rejected_frames},
            {"lateness_p50_ns", stats.lateness_p50_ns},
            {"lateness_p99_ns", stats.lateness_p99_ns},
            {"lateness_max_ns", stats.lateness_max_ns},
            {"static_impulse_Ns", to_json(world.total_static_impulse_Ns())},
            {"mechanical_energy_J", world.mechanical_energy_J()},
            {"cpu_per_step_p50_us", step_cpu_ns.percentile_ns(0.5) / 1e3},
            {"cpu_per_step_p99_us", step_cpu_ns.percentile_ns(0.99) / 1e3},
            {"cpu_per_step_mean_us", step_cpu_ns.mean_ns() / 1e3},
            {"cpu_per_simulated_s", step_cpu_ns.mean_ns() * 1e-9 / world.world_period_s()}}},
          {"config",
           {{"scene", options.scene_path},
            {"world_rate_hz", 1.0 / world.world_period_s()},
            {"coupling", to_string(world.coupling())},
            {"clock", to_string(options.clock)},
            {"phase_ticks", options.phase_ticks},
            {"substeps", world.scene().physics.substeps},
            {"solver_iterations", world.scene().physics.solver_iterations}}}};
}

class WorldDaemon {
 public:
  explicit WorldDaemon(const Options& options)
      : options_(options), scene_(scene_with_overrides(options)), world_(scene_, world_options(options)) {
    if (options.clock == ClockMode::lockstep) {
      const double ticks = world_.world_period_s() * options.haptic_rate_hz;
      if (std::fabs(ticks - std::round(ticks)) > 1e-9 || ticks < 1.0) {
        throw std::runtime_error("in lockstep the world period (" + std::to_string(world_.world_period_s()) +
                                 " s) must be a whole number of haptic ticks at " +
                                 std::to_string(options.haptic_rate_hz) + " Hz");
      }
    }
    if (!options.log_path.empty()) {
      log_file_.emplace(options.log_path);
      if (!*log_file_) throw std::runtime_error("cannot open log file '" + options.log_path + "' for writing");
      log_.emplace(world_);
      log_->write_header(*log_file_);
    }
    link_.emplace(Segment<WorldLinkLayout>::create(world_link_name(options.shm), [&](WorldLinkLayout& layout) {
      layout.config.world_rate_hz = 1.0 / world_.world_period_s();
      layout.config.world_period_s = world_.world_period_s();
      layout.config.phase_ticks = options.phase_ticks;
      layout.config.clock = options.clock;
      layout.config.coupling = options.coupling;
    }));
  }

  int run() {
    std::fprintf(stderr, "world_manager: '%s', %zu objects, %.1f Hz, %s coupling, %s clock, link '%s'\n",
                 options_.scene_path.c_str(), scene_.objects.size(), 1.0 / world_.world_period_s(),
                 to_string(options_.coupling), to_string(options_.clock), (*link_).name().c_str());
    if (options_.coupling == Coupling::impulse) {
      const LightObjects light =
          light_for_impulse_coupling(scene_, world_.world_period_s(), SpidarGeometry{}.max_force_N);
      if (light.count > 0) {
        std::fprintf(stderr,
                     "world_manager: warning: %zu object(s) are light for impulse coupling at %.1f Hz, the lightest "
                     "'%s' (%.3g kg): the device's %.0f N held for one world period would give it %.3g m/s; a push can "
                     "launch it (hard case 10). Use --coupling local or a faster --rate.\n",
                     light.count, 1.0 / world_.world_period_s(), light.lightest_name.c_str(), light.lightest_mass_kg,
                     SpidarGeometry{}.max_force_N, light.lightest_speed_mps);
      }
    }
    const std::uint64_t max_steps =
        options_.duration_s > 0.0 ? static_cast<std::uint64_t>(std::llround(options_.duration_s /
                                                                             world_.world_period_s()))
                                  : UINT64_MAX;
    if (options_.clock == ClockMode::lockstep) {
      run_lockstep(max_steps);
    } else {
      run_realtime(max_steps);
    }
    if (log_file_) {
      log_file_->flush();
      if (!*log_file_) throw std::runtime_error("writing log '" + options_.log_path + "' failed");
    }
    if (!options_.summary_path.empty()) {
      std::ofstream summary(options_.summary_path);
      summary << summary_of(world_, options_, stats_, step_cpu_ns_).dump(2) << '\n';
      if (!summary) throw std::runtime_error("cannot write summary '" + options_.summary_path + "'");
    }
    std::fprintf(stderr, "world_manager: %llu steps, %.3f s simulated\n",
                 static_cast<unsigned long long>(world_.steps_taken()), world_.time_s());
    return 0;
  }

 private:
  static Scene scene_with_overrides(const Options& options) {
    Scene scene = load_scene(options.scene_path);
    if (options.substeps) scene.physics.substeps = *options.substeps;
    return scene;
  }

  static WorldOptions world_options(const Options& options) {
    WorldOptions world;
    world.coupling = options.coupling;
    world.world_rate_hz = options.rate_hz;
    world.world_session = make_world_session();
    return world;
  }

  // One world step: the latest valid haptic report in, a frame of planes out.
  void step() {
    WorldLinkLayout& link = **link_;
    HapticReport incoming{};
    std::uint64_t any = 0;
    const std::int64_t now_ns = monotonic_now_ns();
    if (link.report.try_read(incoming, any)) {
      if (validate(incoming) == FrameError::ok) {
        if (!have_report_ || incoming.haptic_session != report_.haptic_session || incoming.tick != report_.tick) {
          report_fresh_ns_ = now_ns;
        }
        report_ = incoming;
        have_report_ = true;
      } else {
        ++rejected_reports_;
      }
    }
    // A haptic controller that stopped reporting (killed, stalled) no longer knows where the finger is: drop the
    // finger so position coupling stops pushing with a stale sample. Its impulse totals stay as they were, so the
    // ledger applies nothing more from them; a restarted controller starts a new session from zero.
    if (options_.clock == ClockMode::realtime && have_report_ &&
        now_ns - report_fresh_ns_ > haptic_stale_ns()) {
      report_.finger_valid = 0;
    }
    const std::int64_t cpu_before_ns = thread_cpu_now_ns();
    const PlaneFrame& frame = world_.step(have_report_ ? &report_ : nullptr);
    step_cpu_ns_.record(thread_cpu_now_ns() - cpu_before_ns);
    link.planes.write(frame);
    if (log_) log_->write_row(*log_file_);
  }

  void publish_stats(const RealtimeClock* clock) {
    stats_ = loop_stats_now(clock);
    stats_.ticks = world_.steps_taken();
    stats_.rejected_frames = rejected_reports_;
    (*link_)->world_stats.write(stats_);
  }

  void run_lockstep(std::uint64_t max_steps) {
    WorldLinkLayout& link = **link_;
    // The haptic controller drives us. Before it attaches we wait as long as we are not stopped; once it attached,
    // its death ends the run (nobody would ever give us another turn).
    auto keep_waiting = [&] {
      if (g_stop_requested.load()) return false;
      const std::int32_t haptic = link.haptic_pid.load();
      return haptic == 0 || kill(haptic, 0) == 0;
    };
    while (world_.steps_taken() < max_steps) {
      const TurnResult result = link.world_turn.wait_turn(keep_waiting);
      if (result != TurnResult::ok) {
        if (result == TurnResult::peer_gone && !g_stop_requested.load()) {
          std::fprintf(stderr, "world_manager: the haptic controller went away\n");
        }
        break;
      }
      step();
      publish_stats(nullptr);
      link.world_turn.finish();
    }
    publish_stats(nullptr);
  }

  void run_realtime(std::uint64_t max_steps) {
    RealtimeClock clock(world_.world_period_s());
    while (!g_stop_requested.load() && world_.steps_taken() < max_steps) {
      clock.wait_next();
      step();
      publish_stats(&clock);
    }
  }

  const Options& options_;
  Scene scene_;
  World world_;
  std::optional<std::ofstream> log_file_;
  std::optional<WorldLog> log_;
  std::optional<Segment<WorldLinkLayout>> link_;
  // Three world periods without a new report (at least 100 ms, several host stalls) is a haptic controller gone.
  std::int64_t haptic_stale_ns() const {
    return static_cast<std::int64_t>(std::max(3.0 * world_.world_period_s(), 0.1) * 1e9);
  }

  HapticReport report_{};
  bool have_report_ = false;
  std::int64_t report_fresh_ns_ = 0;
  LoopStats stats_;  // the last published snapshot, also written to the summary
  std::uint64_t rejected_reports_ = 0;
  LatencyHistogram step_cpu_ns_;  // CPU time of World::step (coupling + ODE + features), per step
};

}  // namespace
}  // namespace impetus

int main(int argc, char** argv) {
  using namespace impetus;
  Options options;
  CLI::App app{"world_manager: the ODE world of Impetus. Steps a scene at the world rate, applies the haptic "
               "controller's impulses and publishes the planes near the finger."};
  app.add_option("--scene", options.scene_path, "scene file (JSON, see scenes/)")->required()->check(CLI::ExistingFile);
  app.add_option("--rate", options.rate_hz, "world rate in Hz (default: the scene's physics.world_rate_hz)")
      ->check(CLI::PositiveNumber);
  app.add_option("--substeps", options.substeps, "ODE steps per world period (default: the scene's physics.substeps)")
      ->check(CLI::Range(1, 10000));
  app.add_option("--coupling", options.coupling, "impulse (paper §2.2), position (the previous method) or local")
      ->transform(CLI::CheckedTransformer(kCouplingNames, CLI::ignore_case));
  add_clock_flag(app, options.clock);
  app.add_option("--phase", options.phase_ticks, "lockstep: world step i happens at haptic tick i*n + PHASE")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--duration", options.duration_s, "seconds of world time to run (default: until stopped)")
      ->check(CLI::PositiveNumber);
  add_output_flag(app, "--log", options.log_path, "CSV log of every dynamic object per step");
  add_output_flag(app, "--summary", options.summary_path, "JSON summary written at exit (objects, loop statistics)");
  add_shm_flag(app, options.shm);
  app.add_option("--haptic-rate", options.haptic_rate_hz, "haptic rate the lockstep phase is counted in (1000)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  install_stop_handlers();
  try {
    init_ode_once();
    WorldDaemon daemon(options);
    return daemon.run();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "world_manager: error: %s\n", error.what());
    return 1;
  }
}
