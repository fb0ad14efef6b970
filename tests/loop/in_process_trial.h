#pragma once
// One trial with world, haptic and device nodes in this process over the in-process links (DESIGN.md §1.3, §2):
// the same nodes the three daemons run, under the lockstep schedule, on the calling thread.

#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/haptic_node.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/trajectory.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/world_node.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace impetus::test {

struct InProcessTrialOptions {
  std::string scene_path;
  std::string trajectory;
  Coupling coupling = Coupling::impulse;
  std::uint64_t phase_ticks = 0;
  std::filesystem::path out_dir;  // world.csv, haptic.csv and device.csv are written here
};

// Runs the trial to the end of its trajectory; returns the world and haptic halves of summary.json merged.
inline nlohmann::json run_in_process_trial(const InProcessTrialOptions& options) {
  init_ode_once();
  WorldNodeOptions world_options;
  world_options.scene_path = options.scene_path;
  world_options.coupling = options.coupling;
  world_options.clock = ClockMode::lockstep;
  world_options.phase_ticks = options.phase_ticks;
  world_options.log_path = (options.out_dir / "world.csv").string();
  WorldNode world(world_options);
  InProcessWorldLink world_link(world.link_info());
  world.connect(world_link);
  world_link.connect(world);

  HapticNodeOptions haptic_options;
  haptic_options.clock = ClockMode::lockstep;
  haptic_options.log_path = (options.out_dir / "haptic.csv").string();
  InProcessDevicePort port(1.0 / haptic_options.rate_hz);
  SpidarDriver driver(SpidarGeometry{}, port, ClockMode::lockstep, haptic_options.haptic_session);
  HapticNode haptic(haptic_options, world_link, driver);

  DeviceSim sim(SpidarGeometry{}, HardwareParams{}, FingerParams{}, load_trajectory(options.trajectory));
  DeviceNode device(sim, port, (options.out_dir / "device.csv").string(), 1);
  port.connect(device);

  haptic.run();
  nlohmann::json summary = world.summary();
  summary.update(haptic.summary());
  return summary;
}

}  // namespace impetus::test
