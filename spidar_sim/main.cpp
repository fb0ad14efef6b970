// spidar_sim: the SPIDAR device and the human finger, simulated, attached to a running haptic controller's device port
// (DESIGN.md §1 "One device tick"). Plays a scripted trajectory, then detaches cleanly and exits 0.

#include "common/daemon.h"
#include "common/device_port.h"
#include "common/link_names.h"
#include "common/realtime_clock.h"
#include "common/trajectory.h"
#include "spidar_sim/device_sim.h"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

namespace impetus {
namespace {

struct Options {
  std::string trajectory;
  ClockMode clock = ClockMode::realtime;
  std::string log_path;
  std::string shm = "impetus";
  double attach_timeout_s = 10.0;
  HardwareParams hardware;
  FingerParams finger;
};

// Minimum tensions: what the device feels from a haptic controller that sends nothing (it keeps the strings taut).
std::array<double, kStringCount> minimum_tensions(const SpidarGeometry& geometry) {
  std::array<double, kStringCount> tensions{};
  tensions.fill(geometry.tension_min_N);
  return tensions;
}

// Claims the device slot of the port: 0 → our pid. A slot held by a live device is an error; one held by a dead
// device is freed by the haptic controller within a few ticks, so we wait for it.
void claim_port(DevicePortLayout& port, double timeout_s) {
  const auto me = static_cast<std::int32_t>(getpid());
  for (double waited_s = 0.0;; waited_s += 0.01) {
    std::int32_t expected = 0;
    if (port.device_pid.compare_exchange_strong(expected, me)) return;
    if (waited_s > timeout_s) {
      throw std::runtime_error("the device port is held by process " + std::to_string(expected) +
                               " (another spidar_sim?)");
    }
    if (g_stop_requested.load()) throw std::runtime_error("stopped while waiting for the device port");
    usleep(10'000);
  }
}

class DeviceSession {
 public:
  DeviceSession(const Options& options, Segment<DevicePortLayout>& port, DeviceSim& sim)
      : options_(options), port_(port), sim_(sim), session_(static_cast<std::uint64_t>(getpid()) << 20 | 1) {
    if (!options.log_path.empty()) {
      log_.emplace(options.log_path);
      if (!*log_) throw std::runtime_error("cannot open log file '" + options.log_path + "' for writing");
      DeviceSim::write_log_header(*log_);
    }
  }

  // One device tick of dt_s with the latest commanded tensions.
  void step(double dt_s) {
    DeviceCommand command{};
    std::uint64_t any = 0;
    std::array<double, kStringCount> tensions = minimum_tensions(SpidarGeometry{});
    if (port_->command.try_read(command, any) && validate(command) == FrameError::ok) {
      tensions = command.tension_N;
    } else if (any != 0) {
      ++rejected_;
    }
    DeviceState state = sim_.tick(tensions, dt_s);
    state.device_session = session_;
    seal(state);
    port_->state.write(state);
    if (log_) sim_.write_log_row(*log_);
    ++ticks_;
  }

  void publish_stats(const RealtimeClock* clock) {
    LoopStats stats = loop_stats_now(clock);
    stats.ticks = ticks_;
    stats.rejected_frames = rejected_;
    port_->device_stats.write(stats);
  }

  std::uint64_t ticks() const { return ticks_; }
  void flush() {
    if (log_) log_->flush();
  }

 private:
  const Options& options_;
  Segment<DevicePortLayout>& port_;
  DeviceSim& sim_;
  std::uint64_t session_;
  std::optional<std::ofstream> log_;
  std::uint64_t ticks_ = 0;
  std::uint64_t rejected_ = 0;
};

int run(const Options& options) {
  const Trajectory trajectory = load_trajectory(options.trajectory);
  const SpidarGeometry geometry;
  DeviceSim sim(geometry, options.hardware, options.finger, trajectory);

  auto port = open_when_ready<DevicePortLayout>(device_port_name(options.shm), options.attach_timeout_s);
  if (port->clock != options.clock) {
    throw std::runtime_error(std::string("the haptic controller runs --clock ") + to_string(port->clock) +
                             " but spidar_sim was started with --clock " + to_string(options.clock));
  }
  claim_port(*port, options.attach_timeout_s);
  DeviceSession session(options, port, sim);
  std::fprintf(stderr, "spidar_sim: attached to '%s' (%s), trajectory %.3f s\n", port.name().c_str(),
               to_string(options.clock), trajectory.duration_s());

  if (options.clock == ClockMode::lockstep) {
    const double dt_s = port->haptic_period_s;
    for (;;) {
      const TurnResult result =
          port->device_turn.wait_turn([&] { return !g_stop_requested.load() && port.creator_alive(); });
      if (result == TurnResult::shutdown) {
        std::fprintf(stderr, "spidar_sim: the haptic controller ended the session\n");
        break;
      }
      if (result != TurnResult::ok) {
        std::fprintf(stderr, "spidar_sim: %s\n",
                     g_stop_requested.load() ? "stopped" : "the haptic controller went away");
        break;
      }
      if (sim.finished()) {
        // Our last turn carries no new state: the haptic controller sees `detaching` and frees the slot.
        port->detaching.store(1, std::memory_order_release);
        port->device_turn.finish();
        break;
      }
      session.step(dt_s);
      if (session.ticks() % 100 == 0) session.publish_stats(nullptr);
      port->device_turn.finish();
    }
    session.publish_stats(nullptr);
  } else {
    constexpr double kDevicePeriod_s = 1e-3;  // the device's own servo rate; the finger sub-steps inside it
    RealtimeClock clock(kDevicePeriod_s);
    bool haptic_alive = true;
    while (!g_stop_requested.load() && !sim.finished() && haptic_alive) {
      const TickTiming timing = clock.wait_next();
      // Liveness reads /proc: ten times a second is plenty to notice a dead haptic controller.
      if (timing.index % 100 == 0) haptic_alive = port.creator_alive();
      // After a host stall the finger is advanced by the real elapsed time, capped so one tick stays a tick.
      session.step(std::min(timing.elapsed_s, DeviceSim::kMaxTick_s));
      if (timing.index % 100 == 0) session.publish_stats(&clock);
    }
    session.publish_stats(&clock);
    port->detaching.store(1, std::memory_order_release);
  }
  session.flush();
  std::fprintf(stderr, "spidar_sim: detached after %llu ticks (%.3f s simulated)\n",
               static_cast<unsigned long long>(session.ticks()), sim.time_s());
  return 0;
}

}  // namespace
}  // namespace impetus

int main(int argc, char** argv) {
  using namespace impetus;
  Options options;
  CLI::App app{"spidar_sim: a simulated SPIDAR device and finger playing a scripted trajectory against a running "
               "haptic_controller."};
  app.add_option("--trajectory", options.trajectory,
                 "CSV file with header t,x,y,z, or a built-in: tap|press|slide|circle[:key=value,...]")
      ->required();
  add_clock_flag(app, options.clock);
  add_output_flag(app, "--log", options.log_path, "CSV log: time, target, finger, velocity, force, tensions, counts");
  add_shm_flag(app, options.shm);
  app.add_option("--attach-timeout", options.attach_timeout_s, "seconds to wait for the haptic controller's port")
      ->check(CLI::PositiveNumber);
  app.add_option("--hand-stiffness", options.finger.hand_stiffness_Npm, "hand impedance stiffness, N/m (300)")
      ->check(CLI::PositiveNumber);
  app.add_option("--hand-damping", options.finger.hand_damping_Nspm, "hand impedance damping, N·s/m (8)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--finger-mass", options.finger.mass_kg, "finger point mass, kg (0.1)")->check(CLI::PositiveNumber);
  app.add_option("--motor-lag", options.hardware.motor_time_constant_s, "motor time constant, s (0 = ideal)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  install_stop_handlers();
  try {
    return run(options);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "spidar_sim: error: %s\n", error.what());
    return 1;
  }
}
