// SPDX-License-Identifier: Apache-2.0
#include "loop/in_process_trial.h"

#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "common/runtime/cli.h"
#include "common/runtime/log_paths.h"
#include "haptic_controller/device/finger_set.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/haptic_node.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/trajectory.h"
#include "world_manager/engine/ode_runtime.h"
#include "world_manager/world_node.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>
#include <cstdio>
#include <mutex>
#include <stdexcept>

namespace impetus {
namespace {

// The log path for `name` under `dir`, or "" (no log) when no directory was given.
std::string log_path(const std::filesystem::path& dir, const char* name) {
  return dir.empty() ? std::string() : (dir / name).string();
}

// The option's text checked by the validator of the daemon flag it mirrors, so both reject the same values with the
// same words; throws std::invalid_argument "NAME: REASON".
void check_option(const char* name, double value, CLI::Validator validator) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  std::string input = text;
  if (const std::string problem = validator(input); !problem.empty()) {
    throw std::invalid_argument(std::string(name) + ": " + problem);
  }
}

void check_options(const InProcessTrialOptions& options) {
  if (options.world_rate_hz) {
    check_option("world_rate_hz", *options.world_rate_hz,
                 number_in(limits::kMinWorldRate_Hz, limits::kMaxWorldRate_Hz));
  }
  if (options.substeps && (*options.substeps < 1 || *options.substeps > limits::kMaxSubsteps)) {
    throw std::invalid_argument("substeps: must be a whole number from 1 to " +
                                std::to_string(limits::kMaxSubsteps) + ", not " + std::to_string(*options.substeps));
  }
  // NaN stands for "the scene's value" here, as an absent flag does for the daemon.
  if (!std::isnan(options.stiffness_Npm)) {
    check_option("stiffness_Npm", options.stiffness_Npm, positive_number(limits::kMaxStiffness_Npm));
  }
  if (!std::isnan(options.damping_Nspm)) {
    check_option("damping_Nspm", options.damping_Nspm, number_in(0.0, limits::kMaxDamping_Nspm));
  }
  if (options.duration_s != 0.0) check_option("duration_s", options.duration_s, positive_number(kMaxFlagSeconds));
}

}  // namespace

nlohmann::json run_in_process_trial(const InProcessTrialOptions& options) {
  check_options(options);
  // ODE keeps process-wide state that a step uses (its random generator, which QuickStep draws from, and its default
  // threading implementation), so two worlds must not step at once: trials in one process take turns.
  static std::mutex one_trial_at_a_time;
  const std::lock_guard<std::mutex> turn(one_trial_at_a_time);
  init_ode_once();
  WorldNodeOptions world_options;
  world_options.scene_path = options.scene_path;
  world_options.rate_hz = options.world_rate_hz;
  world_options.substeps = options.substeps;
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
  haptic_options.stiffness_Npm = options.stiffness_Npm;
  haptic_options.damping_Nspm = options.damping_Nspm;
  haptic_options.duration_s = options.duration_s;
  // The device: one SPIDAR string set, port and simulated finger per finger (one for a --trajectory trial).
  if (!options.fingers.empty() && !options.trajectory.empty()) {
    throw std::invalid_argument("give trajectory or fingers, not both");
  }
  const std::vector<NamedFinger> fingers = options.fingers.empty()
                                               ? std::vector<NamedFinger>{{"finger", load_trajectory(options.trajectory)}}
                                               : parse_fingers(options.fingers, kMaxFingers);
  double longest_s = 0.0;
  for (const NamedFinger& named : fingers) longest_s = std::max(longest_s, named.trajectory.duration_s());
  std::vector<std::unique_ptr<InProcessDevicePort>> ports;
  std::vector<std::unique_ptr<SpidarDriver>> drivers;
  std::vector<std::unique_ptr<DeviceSim>> sims;
  std::vector<std::unique_ptr<DeviceNode>> devices;
  std::vector<HapticDevice*> finger_devices;
  for (std::size_t k = 0; k < fingers.size(); ++k) {
    ports.push_back(std::make_unique<InProcessDevicePort>(1.0 / haptic_options.rate_hz));
    drivers.push_back(std::make_unique<SpidarDriver>(SpidarGeometry{}, *ports.back(), ClockMode::lockstep,
                                                     haptic_options.haptic_session));
    finger_devices.push_back(drivers.back().get());
    sims.push_back(std::make_unique<DeviceSim>(SpidarGeometry{}, HardwareParams{}, FingerParams{},
                                               fingers[k].trajectory.held_until(longest_s)));
    devices.push_back(std::make_unique<DeviceNode>(
        *sims.back(), *ports.back(),
        endpoint_log_path(log_path(options.out_dir, "device.csv"), static_cast<std::uint32_t>(k)), 1 + k));
    ports.back()->connect(*devices.back());
  }
  std::optional<FingerSet> finger_set;
  if (fingers.size() > 1) finger_set.emplace(finger_devices);
  HapticDevice& device = finger_set ? static_cast<HapticDevice&>(*finger_set) : *drivers[0];
  HapticNode haptic(haptic_options, world_link.attach(static_cast<std::uint32_t>(fingers.size())), device);

  haptic.run();
  nlohmann::json summary = world.summary();
  summary.update(haptic.summary());
  summary.update(devices[0]->summary());
  if (fingers.size() > 1) {
    nlohmann::json per_finger = nlohmann::json::array();
    for (std::size_t k = 0; k < fingers.size(); ++k) {
      nlohmann::json one = devices[k]->summary()["device"];
      one["name"] = fingers[k].name;
      one["trajectory"] = fingers[k].trajectory.description();
      per_finger.push_back(one);
    }
    summary["device"]["fingers"] = per_finger;
  }
  return summary;
}

}  // namespace impetus
