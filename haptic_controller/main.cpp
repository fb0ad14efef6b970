// SPDX-License-Identifier: Apache-2.0
// haptic_controller: the 1 kHz haptic servo (docs/architecture.md §1.2). Parses the flags and runs the process they
// describe (app.h).

#include "common/link/dds/open_world_link.h"
#include "common/runtime/cli.h"
#include "haptic_controller/app.h"
#include "haptic_controller/device/device_registry.h"

#include <optional>
#include <string>

int main(int argc, char** argv) {
  using namespace impetus;
  HapticControllerFlags flags;
  CLI::App app{"haptic_controller: the 1 kHz haptic servo of Impetus. Interpolates the world's planes, renders the "
               "god-object force on the SPIDAR and integrates it into impulses for the world."};
  app.add_option("--rate", flags.options.rate_hz, "servo rate in Hz (1000)")
      ->check(number_in(limits::kMinHapticRate_Hz, limits::kMaxHapticRate_Hz));
  app.add_option("--stiffness", flags.options.stiffness_Npm, "k_p in N/m (default: the scene's)")
      ->check(positive_number(limits::kMaxStiffness_Npm));
  app.add_option("--damping", flags.options.damping_Nspm, "k_d in N·s/m (default: the scene's)")
      ->check(number_in(0.0, limits::kMaxDamping_Nspm));
  add_clock_flag(app, flags.options.clock);
  app.add_option("--duration", flags.options.duration_s, "seconds to run (default: until stopped)")
      ->check(positive_number(kMaxFlagSeconds));
  add_output_flag(app, "--log", flags.options.log_path,
                  "CSV log: finger, proxy, force, accumulated impulse, lateness per tick");
  add_output_flag(app, "--summary", flags.summary_path, "JSON summary written at exit (loop statistics, faults)");
  add_shm_flag(app, flags.shm);
  add_link_flags(app, flags.link_options);
  app.add_option("--world-wait", flags.world_wait_s, "seconds to wait for the world manager's link (10)")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--device", flags.device_spec, "the device: " + device_forms() +
                     " (spidar: the built-in geometry; web: a simulated hand a person steers from the viewer's page, "
                     "with viewer --touch; real time only)");
  app.add_option("--fingers", flags.fingers,
                 "fingers of the device, one endpoint of the world each, 1 to 8 (1); finger "
                 "k's device port is NAME.device (k = 0) or NAME.device<k>")->check(CLI::Range(1u, kMaxFingers));
  app.add_option("--followers", flags.options.followers, "lockstep, the first of several users' controllers on one "
                 "world: wait for this many more (with --world-shm); they follow this one's ticks (0)")
      ->check(CLI::Range(0u, kMaxEndpoints - 1));
  app.add_option("--world-shm", flags.world_shm, "the world link's NAME when it differs from --shm: several users' "
                 "controllers, each with its own --shm for its device, on one world");
  app.add_flag("!--no-realtime-priority", flags.options.realtime_priority, "no SCHED_FIFO and mlockall in real time");
  app.add_option("--meshes-from", flags.mesh_scene,
                 "the world's scene: its meshes are read, so the servo follows their "
                 "triangles between frames (else a mesh's planes are used as sent)");
  app.add_option("--tool-from", flags.tool_scene,
                 "the world's scene: its \"tool\" block is the tool in the hand, held by "
                 "an oriented device (--device grip; docs/tool.md)");
  if (const std::optional<int> status = parse_flags(app, "haptic_controller", argc, argv)) return *status;

  return run_node("haptic_controller", [&] { return run_haptic_controller(flags); });
}
