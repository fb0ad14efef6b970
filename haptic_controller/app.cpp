// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/app.h"

#include "common/link/dds/open_world_link.h"
#include "common/runtime/cli.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/device/hosted_device.h"
#include "haptic_controller/scene_inputs.h"

#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace impetus {

int run_haptic_controller(HapticControllerFlags& flags) {
  flags.options.haptic_session = new_session_id();
  const std::unique_ptr<DeviceType> device_type = parse_device(flags.device_spec);
  read_scene_inputs(flags.mesh_scene, flags.tool_scene, flags.options);
  if (flags.link_options.kind == LinkKind::dds && !flags.world_shm.empty()) {
    throw std::invalid_argument("--world-shm names a shared-memory world link; with --link dds the world is found "
                                "by --dds-domain and --dds-partition");
  }
  std::optional<HostedDevice> device;
  const auto host_device = [&] {
    device.emplace(*device_type, flags.device_spec, flags.shm, flags.options.clock, 1.0 / flags.options.rate_hz,
                   flags.options.haptic_session, flags.fingers);
  };
  // A device in this process (the web hand) first: it refuses a clock it cannot run on before anything waits.
  if (!device_type->uses_device_ports()) host_device();
  // The world link before the device ports: a device starts its motion when its port appears, and the servo can
  // render only once the world serves it (over DDS that takes a discovery). The device ports stay in shared memory
  // on this host either way, one per finger.
  const std::unique_ptr<WorldLinkClient> world =
      open_world_link_client(flags.link_options, flags.world_shm.empty() ? flags.shm : flags.world_shm,
                             flags.options.clock, flags.world_wait_s, flags.fingers);
  if (!device) host_device();
  HapticNode node(flags.options, *world, device->device());
  std::fprintf(stderr, "haptic_controller: %.0f Hz, %s clock, world at %.1f Hz, %s\n", flags.options.rate_hz,
               to_string(flags.options.clock), world->info().world_rate_hz, device->where().c_str());
  const int status = node.run();
  nlohmann::json summary = node.summary();
  if (nlohmann::json link = link_summary(*world, flags.link_options); !link.is_null()) {
    summary["haptic"]["dds"] = link;
  }
  write_summary(flags.summary_path, summary);
  // The first endpoint's figures, a finger's or a tool's (its summary's top level).
  const nlohmann::json& haptic = summary["haptic"];
  std::fprintf(stderr, "haptic_controller: %llu ticks, %llu faults, %llu force clamps, %llu saturations\n",
               haptic.value("ticks", 0ull), haptic.value("faults", 0ull), haptic.value("force_clamps", 0ull),
               static_cast<unsigned long long>(device->device().counters().saturations));
  if (node.duration_reached() && device_type->uses_device_ports()) {
    std::fprintf(stderr, "haptic_controller: warning: the trial stopped at --duration %g s, before the device's "
                 "trajectory ended\n", flags.options.duration_s);
  }
  return status;
}

}  // namespace impetus
