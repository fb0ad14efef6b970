// SPDX-License-Identifier: Apache-2.0
#pragma once
// The nodes of one in-process trial wired together (docs/architecture.md §1.3, §2): a world node, the in-process
// world link (with its delay line), and per user a haptic node and a simulated device of one or more fingers on
// in-process device ports. The scripted trial (in_process_trial.h) runs them to the end; the closed loop
// (simulation.h) ticks them one at a time. Both build them here, so both run the same physics.
//
// Owns every node and link; not copyable. The first user is the lockstep master, the others follow its ticks.

#include "common/contract/frames.h"
#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/haptic_node.h"
#include "loop/in_process_trial.h"
#include "spidar_sim/simulated_fingers.h"
#include "world_manager/world_node.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <mutex>
#include <vector>

namespace impetus {

class InProcessRig {
 public:
  // Checks the options' ranges (std::invalid_argument naming the option), loads the scene (SceneError) and builds the
  // nodes. `fingers` are the first user's; the followers' come from options.followers. The caller holds
  // engine_turn() while building, stepping and destroying a rig.
  InProcessRig(const InProcessTrialOptions& options, std::vector<NamedFinger> fingers);
  InProcessRig(const InProcessRig&) = delete;
  InProcessRig& operator=(const InProcessRig&) = delete;
  ~InProcessRig();

  // ODE keeps process-wide state (its default threading implementation; each world keeps its own random state,
  // restored at each step), so two worlds must never step at once: whoever builds, steps or destroys a rig holds this.
  static std::mutex& engine_turn();

  WorldNode& world() { return *world_; }
  HapticNode& haptic() { return *users_[0]->haptic; }              // the first user's (the lockstep master)
  SimulatedFingers& fingers() { return users_[0]->rig; }           // the first user's device
  double tick_period_s() const { return 1.0 / rate_hz_; }

  // Runs every user's session to its end (the scripted trial): the master's ticks, then the followers finish.
  void run();
  // The first user's session is over (a closed loop stopping): ends it and lets the followers finish.
  void finish();
  // The world, haptic and device halves of summary.json merged, "link" and "followers" (in_process_trial.h).
  nlohmann::json summary() const;

 private:
  // One user: a haptic node and its device, a SPIDAR string set, port and simulated finger per finger.
  struct Controller {
    Controller(const HapticNodeOptions& haptic_options, std::vector<NamedFinger> fingers, InProcessWorldLink& world,
               const std::string& device_log);
    nlohmann::json summary() const;

    WorldLinkClient& link;
    std::vector<std::unique_ptr<InProcessDevicePort>> ports;
    SimulatedFingers rig;
    std::unique_ptr<AssembledDevice> device;
    std::unique_ptr<HapticNode> haptic;
  };

  double rate_hz_;
  InProcessLinkDelay link_delay_;
  LinkLoss link_loss_;
  std::unique_ptr<WorldNode> world_;
  std::unique_ptr<InProcessWorldLink> world_link_;
  std::vector<std::unique_ptr<Controller>> users_;
  bool finished_ = false;
};

}  // namespace impetus
