// SPDX-License-Identifier: Apache-2.0
// haptic_controller: the 1 kHz haptic servo (DESIGN.md §1.2). Parses the flags, creates the device port, opens the
// world link and runs a HapticNode on them; writes the haptic half of summary.json at exit.

#include "common/link/shm/shm_device_port.h"
#include "common/link/shm/shm_world_link.h"
#include "common/runtime/cli.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/haptic_node.h"

int main(int argc, char** argv) {
  using namespace impetus;
  HapticNodeOptions options;
  std::string summary_path;
  std::string shm = "impetus";
  double world_wait_s = 10.0;
  std::string device_spec = "spidar";
  CLI::App app{"haptic_controller: the 1 kHz haptic servo of Impetus. Interpolates the world's planes, renders the "
               "god-object force on the SPIDAR and integrates it into impulses for the world."};
  app.add_option("--rate", options.rate_hz, "servo rate in Hz (1000)")
      ->check(number_in(limits::kMinHapticRate_Hz, limits::kMaxHapticRate_Hz));
  app.add_option("--stiffness", options.stiffness_Npm, "k_p in N/m (default: the scene's)")
      ->check(positive_number(limits::kMaxStiffness_Npm));
  app.add_option("--damping", options.damping_Nspm, "k_d in N·s/m (default: the scene's)")
      ->check(number_in(0.0, limits::kMaxDamping_Nspm));
  add_clock_flag(app, options.clock);
  app.add_option("--duration", options.duration_s, "seconds to run (default: until stopped)")
      ->check(positive_number(kMaxFlagSeconds));
  add_output_flag(app, "--log", options.log_path,
                  "CSV log: finger, proxy, force, accumulated impulse, lateness per tick");
  add_output_flag(app, "--summary", summary_path, "JSON summary written at exit (loop statistics, faults)");
  add_shm_flag(app, shm);
  app.add_option("--world-wait", world_wait_s, "seconds to wait for the world manager's link (10)")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--device", device_spec, "spidar (the built-in geometry) or spidar:FILE.json (a device file)");
  app.add_flag("!--no-realtime-priority", options.realtime_priority,
               "do not ask for SCHED_FIFO and mlockall in real time");
  CLI11_PARSE(app, argc, argv);

  return run_node("haptic_controller", [&] {
    options.haptic_session = new_session_id();
    const SpidarDevice spidar = parse_device_spec(device_spec);
    ShmDevicePortHost port(shm, options.clock, 1.0 / options.rate_hz,
                           {geometry_hash(spidar.geometry), spidar.source});
    SpidarDriver device(spidar.geometry, port, options.clock, options.haptic_session);
    ShmWorldLinkClient world(shm, options.clock, world_wait_s);
    HapticNode node(options, world, device);
    std::fprintf(stderr, "haptic_controller: %.0f Hz, %s clock, world at %.1f Hz, device port '%s'\n",
                 options.rate_hz, to_string(options.clock), world.info().world_rate_hz, port.name().c_str());
    const int status = node.run();
    write_summary(summary_path, node.summary());
    const ServoCounters& counters = node.servo().counters();
    std::fprintf(stderr, "haptic_controller: %llu ticks, %llu faults, %llu force clamps, %llu saturations\n",
                 static_cast<unsigned long long>(counters.ticks), static_cast<unsigned long long>(counters.faults),
                 static_cast<unsigned long long>(counters.force_clamps),
                 static_cast<unsigned long long>(device.counters().saturations));
    return status;
  });
}
