// SPDX-License-Identifier: Apache-2.0
// Throughput of the in-process loop (loop/in_process_trial.h): the tap trial's world, haptic controller and simulated
// device on one thread under the lockstep schedule, without logs. Prints ticks per second for the 2 s tap trial and
// the steady state of a long one (the tap, then a 20 s hold: (long − short) ticks over (long − short) wall time), and
// what one device tick costs alone (DeviceSim: one exact finger step per tick). Asserts nothing.
//
//   bench_in_process [SCENE=scenes/tap.json]

#include "loop/in_process_trial.h"
#include "spidar_sim/device_sim.h"
#include "spidar_sim/trajectory.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

struct Run {
  double ticks = 0.0;
  double wall_s = 0.0;
};

Run run(const std::string& scene, const std::string& trajectory) {
  impetus::InProcessTrialOptions options;
  options.scene_path = scene;
  options.trajectory = trajectory;
  const auto start = std::chrono::steady_clock::now();
  const nlohmann::json summary = impetus::run_in_process_trial(options);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {summary["device"]["ticks"].get<double>(), wall_s};
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int bench(int argc, char** argv) {
  if (argc > 1 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::printf("usage: bench_in_process [SCENE=scenes/tap.json]\nThroughput of the in-process loop on the tap trial, "
                "without logs, and of the simulated device alone. Asserts nothing.\n");
    return 0;
  }
  const std::string scene = argc > 1 ? argv[1] : std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  constexpr int kRuns = 5;
  std::vector<double> short_wall, long_wall;
  Run short_run, long_run;
  for (int k = 0; k < kRuns; ++k) {
    short_run = run(scene, "tap");
    long_run = run(scene, "tap:hold=20");
    short_wall.push_back(short_run.wall_s);
    long_wall.push_back(long_run.wall_s);
  }
  const double short_s = median(short_wall), long_s = median(long_wall);
  std::printf("in-process loop, tap trial, no logs (median of %d): %.0f ticks in %.2f ms: %.0f ticks/s; "
              "tap:hold=20: %.0f ticks/s; steady state %.0f ticks/s (%.2f us a tick)\n",
              kRuns, short_run.ticks, short_s * 1e3, short_run.ticks / short_s, long_run.ticks / long_s,
              (long_run.ticks - short_run.ticks) / (long_s - short_s),
              (long_s - short_s) / (long_run.ticks - short_run.ticks) * 1e6);

  // The simulated device alone: the finger's ten sub-steps a tick (string forces, target, integration).
  impetus::DeviceSim device(impetus::SpidarGeometry{}, impetus::HardwareParams{}, impetus::FingerParams{},
                            impetus::load_trajectory("tap:hold=200"));
  const std::array<double, impetus::kStringCount> tensions_N{1.0, 1.0, 1.0, 1.0};
  constexpr int kDeviceTicks = 200'000;
  std::int64_t checksum = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < kDeviceTicks; ++k) checksum += device.tick(tensions_N, 1e-3).encoder_counts[0];
  const double device_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("simulated device alone: %.0f ns a tick (%d ticks; checksum %lld)\n", device_s / kDeviceTicks * 1e9,
              kDeviceTicks, static_cast<long long>(checksum));
  return 0;
}

int main(int argc, char** argv) {
  try {
    return bench(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_in_process: %s\n", error.what());
    return 1;
  }
}
