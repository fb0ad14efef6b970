// SPDX-License-Identifier: Apache-2.0
#include "loop/in_process_trial.h"

#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/haptic_node.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/trajectory.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/world_node.h"

namespace impetus {
namespace {

// The log path for `name` under `dir`, or "" (no log) when no directory was given.
std::string log_path(const std::filesystem::path& dir, const char* name) {
  return dir.empty() ? std::string() : (dir / name).string();
}

}  // namespace

nlohmann::json run_in_process_trial(const InProcessTrialOptions& options) {
  init_ode_once();
  WorldNodeOptions world_options;
  world_options.scene_path = options.scene_path;
  world_options.coupling = options.coupling;
  world_options.clock = ClockMode::lockstep;
  world_options.phase_ticks = options.phase_ticks;
  world_options.log_path = log_path(options.out_dir, "world.csv");
  WorldNode world(world_options);
  InProcessWorldLink world_link(world.link_info());
  world.connect(world_link);
  world_link.connect(world);

  HapticNodeOptions haptic_options;
  haptic_options.clock = ClockMode::lockstep;
  haptic_options.log_path = log_path(options.out_dir, "haptic.csv");
  InProcessDevicePort port(1.0 / haptic_options.rate_hz);
  SpidarDriver driver(SpidarGeometry{}, port, ClockMode::lockstep, haptic_options.haptic_session);
  HapticNode haptic(haptic_options, world_link, driver);

  DeviceSim sim(SpidarGeometry{}, HardwareParams{}, FingerParams{}, load_trajectory(options.trajectory));
  DeviceNode device(sim, port, log_path(options.out_dir, "device.csv"), 1);
  port.connect(device);

  haptic.run();
  nlohmann::json summary = world.summary();
  summary.update(haptic.summary());
  summary.update(device.summary());
  return summary;
}

}  // namespace impetus
