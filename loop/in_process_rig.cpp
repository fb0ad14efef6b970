// SPDX-License-Identifier: Apache-2.0
#include "loop/in_process_rig.h"

#include "common/runtime/cli.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/log_paths.h"
#include "world_manager/engine/engine_registry.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace impetus {
namespace {

// The log path for `name` under `dir`, or "" (no log) when no directory was given.
std::string log_path(const std::filesystem::path& dir, const std::string& name) {
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
  auto out_of_range = [](const char* option, const char* what, double lowest, double highest, double value) {
    char text[200];
    std::snprintf(text, sizeof text, "%s: %s must be between %g and %g, not %.17g", option, what, lowest, highest,
                  value);
    return std::invalid_argument(text);
  };
  if (!(options.link_loss >= 0.0 && options.link_loss <= kMaxLinkLoss)) {
    throw out_of_range("link_loss", "the fraction of packets the link loses", 0.0, kMaxLinkLoss, options.link_loss);
  }
  if (!(options.link_loss_burst >= 1.0 && options.link_loss_burst <= kMaxLossBurst)) {
    throw out_of_range("link_loss_burst", "the mean run of lost packets", 1.0, kMaxLossBurst, options.link_loss_burst);
  }
}

}  // namespace

InProcessRig::Controller::Controller(const HapticNodeOptions& haptic_options, std::vector<NamedFinger> fingers,
                                     InProcessWorldLink& world, const std::string& device_log)
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
nlohmann::json InProcessRig::Controller::summary() const {
  nlohmann::json out = haptic->summary();
  out.update(rig.summary());
  return out;
}

std::mutex& InProcessRig::engine_turn() {
  static std::mutex turn;
  return turn;
}

InProcessRig::InProcessRig(const InProcessTrialOptions& options, std::vector<NamedFinger> fingers)
    : rate_hz_(HapticNodeOptions{}.rate_hz) {  // every controller runs at the default rate
  check_options(options);
  prepare_engines();
  WorldNodeOptions world_options;
  world_options.scene_path = options.scene_path;
  world_options.scene_text = options.scene_text;
  world_options.rate_hz = options.world_rate_hz;
  world_options.substeps = options.substeps;
  world_options.engine = options.engine;
  world_options.coupling = options.coupling;
  world_options.passivity = options.passivity;
  world_options.clock = ClockMode::lockstep;
  world_options.phase_ticks = options.phase_ticks;
  world_options.log_path = log_path(options.out_dir, "world.csv");
  world_ = std::make_unique<WorldNode>(world_options);
  // The delay in whole haptic ticks, to the nearest: the lockstep schedule has no time between two ticks.
  link_delay_.delay_ticks = static_cast<std::uint64_t>(std::llround(options.link_delay_s * rate_hz_));
  link_delay_.ticks_per_world_step =
      LockstepSchedule::ticks_per_world_step(world_->link_info().world_period_s, rate_hz_);
  link_loss_.rate = options.link_loss;
  link_loss_.burst_packets = options.link_loss_burst;
  world_link_ = std::make_unique<InProcessWorldLink>(world_->link_info(), link_delay_, link_loss_);
  world_->connect(*world_link_);
  world_link_->connect(*world_);

  const std::size_t user_count = 1 + options.followers.size();
  for (std::size_t u = 0; u < user_count; ++u) {
    const std::string prefix = u == 0 ? "" : "user" + std::to_string(u) + ".";
    HapticNodeOptions haptic_options;
    haptic_options.clock = ClockMode::lockstep;
    haptic_options.log_path = log_path(options.out_dir, prefix + "haptic.csv");
    haptic_options.stiffness_Npm = options.stiffness_Npm;
    haptic_options.damping_Nspm = options.damping_Nspm;
    haptic_options.duration_s = options.duration_s;
    haptic_options.haptic_session = 1 + u;
    haptic_options.stop = options.stop;
    haptic_options.followers = u == 0 ? static_cast<std::uint32_t>(options.followers.size()) : 0;
    std::vector<NamedFinger> user_fingers =
        u > 0 ? parse_fingers(options.followers[u - 1], kMaxFingers) : std::move(fingers);
    users_.push_back(std::make_unique<Controller>(haptic_options, std::move(user_fingers), *world_link_,
                                                  log_path(options.out_dir, prefix + "device.csv")));
    if (u > 0) world_link_->connect_follower(users_.back()->link, *users_.back()->haptic);
  }
}

InProcessRig::~InProcessRig() = default;

void InProcessRig::run() {
  users_[0]->haptic->run();
  finished_ = true;
  for (std::size_t u = 1; u < users_.size(); ++u) users_[u]->haptic->run();  // their session is over: they finish
}

void InProcessRig::finish() {
  if (finished_) return;
  finished_ = true;
  users_[0]->haptic->finish_lockstep();
  users_[0]->haptic->close();
  for (std::size_t u = 1; u < users_.size(); ++u) users_[u]->haptic->run();
}

nlohmann::json InProcessRig::summary() const {
  nlohmann::json summary = world_->summary();
  summary.update(users_[0]->summary());
  summary["link"] = {
      {"delay_s", static_cast<double>(link_delay_.delay_ticks) / rate_hz_},
      {"delay_ticks", link_delay_.delay_ticks},
      {"dropped", world_link_->dropped()},
      {"loss", link_loss_.rate},
      {"loss_burst_packets", link_loss_.burst_packets},
      {"lost_frames", world_link_->lost_frames()},
      {"lost_reports", world_link_->lost_reports()},
  };
  if (users_.size() > 1) {
    nlohmann::json followers = nlohmann::json::array();
    for (std::size_t u = 1; u < users_.size(); ++u) followers.push_back(users_[u]->summary());
    summary["followers"] = followers;
  }
  return summary;
}

}  // namespace impetus
