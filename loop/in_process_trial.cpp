// SPDX-License-Identifier: Apache-2.0
#include "loop/in_process_trial.h"

#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "common/runtime/cli.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/log_paths.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/haptic_node.h"
#include "spidar_sim/simulated_fingers.h"
#include "world_manager/engine/engine_registry.h"
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
  // Written out rather than through a flag's validator: no daemon flag mirrors it, and the message names the unit.
  if (!(options.link_delay_s >= 0.0 && options.link_delay_s <= kMaxLinkDelay_s)) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", options.link_delay_s);
    throw std::invalid_argument(std::string("link_delay_s: the link's one-way delay must be between 0 and ") +
                                std::to_string(static_cast<int>(kMaxLinkDelay_s)) + " s, not " + text);
  }
}

// One user: a haptic node and its device, a SPIDAR string set, port and simulated finger per finger.
struct Controller {
  Controller(const HapticNodeOptions& haptic_options, std::vector<NamedFinger> fingers, InProcessWorldLink& world,
             const std::string& device_log)
      : link(world.attach(static_cast<std::uint32_t>(fingers.size()))),
        rig(std::move(fingers), SpidarGeometry{}, HardwareParams{}, FingerParams{}) {
    // Members in this order: the nodes and drivers go before the ports they hold.
    // The built-in SPIDAR: the simulated one beside it has the same geometry, so the ports need no description.
    const std::unique_ptr<DeviceType> type = parse_device("spidar");
    std::vector<DevicePortHost*> port_list;
    for (std::size_t k = 0; k < rig.size(); ++k) {
      ports.push_back(std::make_unique<InProcessDevicePort>(1.0 / haptic_options.rate_hz));
      port_list.push_back(ports.back().get());
      ports.back()->connect(rig.attach(k, *ports.back(), device_log, 1 + k));
    }
    device = std::make_unique<AssembledDevice>(*type, port_list, ClockMode::lockstep, haptic_options.haptic_session);
    haptic = std::make_unique<HapticNode>(haptic_options, link, device->device());
  }

  // The haptic and device halves of its summary (a device of several fingers lists each under "device"."fingers").
  nlohmann::json summary() const {
    nlohmann::json out = haptic->summary();
    out.update(rig.summary());
    return out;
  }

  WorldLinkClient& link;
  std::vector<std::unique_ptr<InProcessDevicePort>> ports;
  SimulatedFingers rig;
  std::unique_ptr<AssembledDevice> device;
  std::unique_ptr<HapticNode> haptic;
};

}  // namespace

nlohmann::json run_in_process_trial(const InProcessTrialOptions& options) {
  check_options(options);
  // ODE keeps process-wide state that a step uses (its random generator, which QuickStep draws from, and its default
  // threading implementation), so two worlds must not step at once: trials in one process take turns.
  static std::mutex one_trial_at_a_time;
  const std::lock_guard<std::mutex> turn(one_trial_at_a_time);
  prepare_engines();
  WorldNodeOptions world_options;
  world_options.scene_path = options.scene_path;
  world_options.rate_hz = options.world_rate_hz;
  world_options.substeps = options.substeps;
  world_options.coupling = options.coupling;
  world_options.clock = ClockMode::lockstep;
  world_options.phase_ticks = options.phase_ticks;
  world_options.log_path = log_path(options.out_dir, "world.csv");
  WorldNode world(world_options);
  const HapticNodeOptions haptic_defaults;  // every controller runs at the default rate
  InProcessLinkDelay link_delay;
  // The delay in whole haptic ticks, to the nearest: the lockstep schedule has no time between two ticks.
  link_delay.delay_ticks = static_cast<std::uint64_t>(std::llround(options.link_delay_s * haptic_defaults.rate_hz));
  link_delay.ticks_per_world_step =
      LockstepSchedule::ticks_per_world_step(world.link_info().world_period_s, haptic_defaults.rate_hz);
  InProcessWorldLink world_link(world.link_info(), link_delay);
  world.connect(world_link);
  world_link.connect(world);

  // One controller per user: the first is the lockstep master, the others follow its ticks (docs/architecture.md §3).
  std::vector<std::unique_ptr<Controller>> users;
  const std::size_t user_count = 1 + options.followers.size();
  for (std::size_t u = 0; u < user_count; ++u) {
    const std::string prefix = u == 0 ? "" : "user" + std::to_string(u) + ".";
    HapticNodeOptions haptic_options;
    haptic_options.clock = ClockMode::lockstep;
    haptic_options.log_path = log_path(options.out_dir, (prefix + "haptic.csv").c_str());
    haptic_options.stiffness_Npm = options.stiffness_Npm;
    haptic_options.damping_Nspm = options.damping_Nspm;
    haptic_options.duration_s = options.duration_s;
    haptic_options.haptic_session = 1 + u;
    haptic_options.stop = options.stop;
    haptic_options.followers = u == 0 ? static_cast<std::uint32_t>(options.followers.size()) : 0;
    std::vector<NamedFinger> fingers = u > 0 ? parse_fingers(options.followers[u - 1], kMaxFingers)
                                              : load_fingers(options.trajectory, options.fingers);
    users.push_back(std::make_unique<Controller>(haptic_options, std::move(fingers), world_link,
                                                 log_path(options.out_dir, (prefix + "device.csv").c_str())));
    if (u > 0) world_link.connect_follower(users.back()->link, *users.back()->haptic);
  }

  users[0]->haptic->run();
  for (std::size_t u = 1; u < users.size(); ++u) users[u]->haptic->run();  // their session is over: they finish
  nlohmann::json summary = world.summary();
  summary.update(users[0]->summary());
  summary["link"] = {
      {"delay_s", static_cast<double>(link_delay.delay_ticks) / haptic_defaults.rate_hz},
      {"delay_ticks", link_delay.delay_ticks},
      {"dropped", world_link.dropped()},
  };
  if (users.size() > 1) {
    nlohmann::json followers = nlohmann::json::array();
    for (std::size_t u = 1; u < users.size(); ++u) followers.push_back(users[u]->summary());
    summary["followers"] = followers;
  }
  return summary;
}

}  // namespace impetus
