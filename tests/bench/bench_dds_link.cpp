// SPDX-License-Identifier: Apache-2.0
// One-way latency of the world link, DDS beside shared memory: a world end publishes a one-plane frame every 2 ms
// with its CLOCK_MONOTONIC send time inside, a controller end publishes a one-entry report every 1 ms likewise, and
// each side records send → receive_frame()/latest_report() as the nodes would see it (DDS: including the client's
// sender thread, which hands the newest report to DDS once a millisecond). Both ends poll every 20 µs, which adds at
// most that. The two ends may run in different network namespaces of one host (they share CLOCK_MONOTONIC).
// Prints p50/p99/max; asserts nothing.
//
//   bench_dds_link [--link dds|shm] [--seconds S] [--role both|world|controller] [--partition NAME] [--secure DIR]
//   --secure DIR: a secured DDS link (DDS Security), DIR made by scripts/dds_security.sh DIR world controller.
//   role both (default): the controller end in a child process; world and controller: one end each, for
//   `ip netns exec` on two hosts (start the world first).

#include "common/link/dds/dds_world_link.h"
#include "common/link/shm/shm_world_link.h"
#include "common/runtime/loop_stats.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

namespace {

using namespace impetus;

constexpr std::chrono::microseconds kPoll{20};
constexpr std::int64_t kFramePeriod_ns = 2'000'000;
constexpr std::int64_t kReportPeriod_ns = 1'000'000;

struct Options {
  std::string link = "dds";
  double seconds = 5.0;
  std::string role = "both";
  std::string partition = "impetus_bench_" + std::to_string(getpid());
  std::string secure_dir;  // empty: an open link
};

// This end's DDS options: with --secure, the world's or the controller's folder.
DdsLinkOptions dds_options(const Options& options, const char* role) {
  DdsLinkOptions dds;
  dds.partition = options.partition;
  if (!options.secure_dir.empty()) dds.security_dir = options.secure_dir + "/" + role;
  return dds;
}

double now_s() { return static_cast<double>(monotonic_now_ns()) * 1e-9; }

void print(const char* what, const Options& options, const LatencyHistogram& latency) {
  std::printf("%s%s link, %s: %llu samples, p50 %.1f us, p99 %.1f us, max %.1f us\n",
              options.secure_dir.empty() ? "" : "secured ", options.link.c_str(), what,
              static_cast<unsigned long long>(latency.count()), latency.percentile_ns(0.5) / 1e3,
              latency.percentile_ns(0.99) / 1e3, latency.max_ns() / 1e3);
  std::fflush(stdout);
}

int run_world(const Options& options) {
  WorldLinkInfo info;
  info.world_rate_hz = 500.0;
  info.world_period_s = 0.002;
  info.clock = ClockMode::realtime;
  std::unique_ptr<WorldLinkServer> link;
  if (options.link == "dds") {
    link = std::make_unique<DdsWorldLinkServer>(dds_options(options, "world"), info);
  } else {
    link = std::make_unique<ShmWorldLinkServer>(options.partition, info);
  }
  static PlaneFrame frame{};
  frame.world_period_s = info.world_period_s;
  frame.plane_count = 1;
  frame.planes[0].object_id = 0;
  frame.planes[0].normal = {0.0, 0.0, 1.0};
  LatencyHistogram latency;
  HapticReport report{};
  std::uint64_t last_tick = 0;
  // Runs until the controller has reported for `seconds` (its first report starts the clock), plus a margin.
  std::int64_t start_ns = 0;
  std::int64_t next_frame_ns = monotonic_now_ns();
  const std::int64_t give_up_ns = monotonic_now_ns() + static_cast<std::int64_t>((options.seconds + 30.0) * 1e9);
  for (;;) {
    const std::int64_t now = monotonic_now_ns();
    if (now >= next_frame_ns) {
      ++frame.frame_index;
      frame.world_time_s = now_s();
      link->publish_frame(0, frame);
      next_frame_ns += kFramePeriod_ns;
    }
    if (link->latest_report(0, report) && report.haptic_session != 0 && report.tick != last_tick) {
      latency.record(monotonic_now_ns() - static_cast<std::int64_t>(report.haptic_time_s * 1e9));
      last_tick = report.tick;
      if (start_ns == 0) start_ns = now;
    }
    if ((start_ns != 0 && now - start_ns > static_cast<std::int64_t>((options.seconds + 0.5) * 1e9)) ||
        now > give_up_ns) {
      break;
    }
    std::this_thread::sleep_for(kPoll);
  }
  print("report controller -> world (1 entry)", options, latency);
  return latency.count() > 0 ? 0 : 1;
}

int run_controller(const Options& options) {
  std::unique_ptr<WorldLinkClient> link;
  if (options.link == "dds") {
    link = std::make_unique<DdsWorldLinkClient>(dds_options(options, "controller"), ClockMode::realtime, 30.0, 1);
  } else {
    link = std::make_unique<ShmWorldLinkClient>(options.partition, ClockMode::realtime, 30.0, 1);
  }
  static PlaneFrame frame{};
  HapticReport report{};
  report.haptic_session = 1;
  report.finger_valid = 1;
  report.entry_count = 1;
  report.entries[0].object_id = 0;
  LatencyHistogram latency;
  const std::int64_t end_ns = monotonic_now_ns() + static_cast<std::int64_t>(options.seconds * 1e9);
  std::int64_t next_report_ns = monotonic_now_ns();
  while (monotonic_now_ns() < end_ns) {
    if (link->receive_frame(0, frame)) {
      latency.record(monotonic_now_ns() - static_cast<std::int64_t>(frame.world_time_s * 1e9));
    }
    const std::int64_t now = monotonic_now_ns();
    if (now >= next_report_ns) {
      ++report.tick;
      report.haptic_time_s = now_s();
      link->publish_report(report);
      next_report_ns += kReportPeriod_ns;
    }
    std::this_thread::sleep_for(kPoll);
  }
  // Stay a moment so the last reports reach the world before this end leaves.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  print("frame world -> controller (1 plane)", options, latency);
  return latency.count() > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    const bool has_value = k + 1 < argc;
    if (arg == "--link" && has_value) {
      options.link = argv[++k];
    } else if (arg == "--seconds" && has_value) {
      options.seconds = std::atof(argv[++k]);
    } else if (arg == "--role" && has_value) {
      options.role = argv[++k];
    } else if (arg == "--partition" && has_value) {
      options.partition = argv[++k];
    } else if (arg == "--secure" && has_value) {
      options.secure_dir = argv[++k];
    } else {
      std::fprintf(stderr,
                   "usage: bench_dds_link [--link dds|shm] [--seconds S] [--role both|world|controller] "
                   "[--partition NAME] [--secure DIR]\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  if ((options.link != "dds" && options.link != "shm") || !(options.seconds > 0.0) ||
      (options.role != "both" && options.role != "world" && options.role != "controller")) {
    std::fprintf(stderr, "bench_dds_link: bad --link, --seconds or --role (see --help)\n");
    return 2;
  }
  try {
    if (options.role == "world") return run_world(options);
    if (options.role == "controller") return run_controller(options);
    const pid_t controller = fork();
    if (controller == 0) {
      // Let the world end come up first (the shared-memory client would otherwise wait for the segment anyway).
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      _exit(run_controller(options));
    }
    const int world_status = run_world(options);
    int status = 0;
    waitpid(controller, &status, 0);
    return world_status != 0 ? world_status : (WIFEXITED(status) ? WEXITSTATUS(status) : 1);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_dds_link: %s\n", error.what());
    return 1;
  }
}
