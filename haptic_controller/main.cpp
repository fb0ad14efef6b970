// SPDX-License-Identifier: Apache-2.0
// haptic_controller: the 1 kHz haptic servo (docs/architecture.md §1.2). Parses the flags, hosts the device, opens
// the world link and runs a HapticNode on them; writes the haptic half of summary.json at exit.

#include "common/link/dds/open_world_link.h"
#include "common/runtime/cli.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/device/hosted_device.h"
#include "haptic_controller/haptic_node.h"
#include "haptic_controller/scene_inputs.h"

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

int main(int argc, char** argv) {
  using namespace impetus;
  HapticNodeOptions options;
  std::string summary_path;
  std::string shm = "impetus";
  double world_wait_s = 10.0;
  std::string device_spec = "spidar";
  std::string world_shm;  // "": the same as --shm
  unsigned fingers = 1;
  std::string mesh_scene;
  std::string tool_scene;
  LinkOptions link_options;
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
  add_link_flags(app, link_options);
  app.add_option("--world-wait", world_wait_s, "seconds to wait for the world manager's link (10)")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--device", device_spec, "the device: " + device_forms() +
                     " (spidar: the built-in geometry; web: a simulated hand a person steers from the viewer's page, "
                     "with viewer --touch; real time only)");
  app.add_option("--fingers", fingers, "fingers of the device, one endpoint of the world each, 1 to 8 (1); finger "
                 "k's device port is NAME.device (k = 0) or NAME.device<k>")->check(CLI::Range(1u, kMaxFingers));
  app.add_option("--followers", options.followers, "lockstep, the first of several users' controllers on one "
                 "world: wait for this many more (with --world-shm); they follow this one's ticks (0)")
      ->check(CLI::Range(0u, kMaxEndpoints - 1));
  app.add_option("--world-shm", world_shm, "the world link's NAME when it differs from --shm: several users' "
                 "controllers, each with its own --shm for its device, on one world");
  app.add_flag("!--no-realtime-priority", options.realtime_priority, "no SCHED_FIFO and mlockall in real time");
  app.add_option("--meshes-from", mesh_scene, "the world's scene: its meshes are read, so the servo follows their "
                 "triangles between frames (else a mesh's planes are used as sent)");
  app.add_option("--tool-from", tool_scene, "the world's scene: its \"tool\" block is the tool in the hand, held by "
                 "an oriented device (--device grip; docs/tool.md)");
  if (const std::optional<int> status = parse_flags(app, "haptic_controller", argc, argv)) return *status;

  return run_node("haptic_controller", [&] {
    options.haptic_session = new_session_id();
    const std::unique_ptr<DeviceType> device_type = parse_device(device_spec);
    read_scene_inputs(mesh_scene, tool_scene, options);
    if (link_options.kind == LinkKind::dds && !world_shm.empty()) {
      throw std::invalid_argument("--world-shm names a shared-memory world link; with --link dds the world is found "
                                  "by --dds-domain and --dds-partition");
    }
    std::optional<HostedDevice> device;
    const auto host_device = [&] {
      device.emplace(*device_type, device_spec, shm, options.clock, 1.0 / options.rate_hz, options.haptic_session,
                     fingers);
    };
    // A device in this process (the web hand) first: it refuses a clock it cannot run on before anything waits.
    if (!device_type->uses_device_ports()) host_device();
    // The world link before the device ports: a device starts its motion when its port appears, and the servo can
    // render only once the world serves it (over DDS that takes a discovery). The device ports stay in shared memory
    // on this host either way, one per finger.
    const std::unique_ptr<WorldLinkClient> world = open_world_link_client(
        link_options, world_shm.empty() ? shm : world_shm, options.clock, world_wait_s, fingers);
    if (!device) host_device();
    HapticNode node(options, *world, device->device());
    std::fprintf(stderr, "haptic_controller: %.0f Hz, %s clock, world at %.1f Hz, %s\n", options.rate_hz,
                 to_string(options.clock), world->info().world_rate_hz, device->where().c_str());
    const int status = node.run();
    nlohmann::json summary = node.summary();
    if (nlohmann::json link = link_summary(*world, link_options); !link.is_null()) summary["haptic"]["dds"] = link;
    write_summary(summary_path, summary);
    // The first endpoint's figures, a finger's or a tool's (its summary's top level).
    const nlohmann::json& haptic = summary["haptic"];
    std::fprintf(stderr, "haptic_controller: %llu ticks, %llu faults, %llu force clamps, %llu saturations\n",
                 haptic.value("ticks", 0ull), haptic.value("faults", 0ull), haptic.value("force_clamps", 0ull),
                 static_cast<unsigned long long>(device->device().counters().saturations));
    if (node.duration_reached() && device_type->uses_device_ports()) {
      std::fprintf(stderr, "haptic_controller: warning: the trial stopped at --duration %g s, before the device's "
                   "trajectory ended\n", options.duration_s);
    }
    return status;
  });
}
