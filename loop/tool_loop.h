// SPDX-License-Identifier: Apache-2.0
#pragma once
// A tool in the hand against the world, in one process and in lockstep (docs/tool.md): the nodes of the daemons wired
// together as a finger's in-process trial wires them (in_process_rig.h). The world node and the haptic node share an
// in-process world link; the haptic node serves the scene's tool ("tool" block) with its tool servo
// (haptic_controller/tool/tool_servo.h) on the 8-string grip SPIDAR: the driver at the host end of an in-process device
// port (haptic_controller/device/grip_port_driver.h), the simulated motors, strings and the hand holding the grip at
// the device end (spidar_sim/grip_node.h). The caller moves the hand's target pose between ticks, as the point
// finger's closed loop (simulation.h) moves a finger's target.
//
// Each tick t (time t·T, T = 1 ms) is the haptic node's lockstep tick:
//  1. the device's tick on its port (its hand toward the target pose under the last tensions), and its eight encoder
//     counts → the driver's pose of the grip;
//  2. the tool servo: the tool's proxy, the wrench on the grip, the reaction booked per object;
//  3. the wrench → the driver's eight tensions → the port, for the device's next tick; the report → the world;
//  4. every world period (ticks 0, n, 2n, …; n = haptic rate / world rate) the world steps on the newest report and
//     its frame reaches the servo.
// The schedule is every lockstep run's, so runs are bitwise reproducible.
//
// Frames: world, SI; a pose is the grip's centre and orientation (grip → world). Not thread-safe; ODE's process-wide
// state is guarded by the in-process rig's engine turn (in_process_rig.h), held while building, stepping and
// destroying.

#include "common/contract/frames.h"
#include "common/hand/grip_hand.h"
#include "common/shape/shape.h"
#include "common/spidar/grip_geometry.h"
#include "common/spidar/grip_strings.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace impetus {

struct ToolLoopOptions {
  std::string scene_path;  // the scene file, or with scene_text the name its messages use
  std::string scene_text;  // the scene's JSON text, if given (then read instead of the file); needs a "tool" block
  // Impulse or local (paper §2.2, §6.3). Position coupling samples one point per endpoint, which a tool is not:
  // refused.
  Coupling coupling = Coupling::local;
  std::optional<double> world_rate_hz;  // overrides the scene's; a haptic tick must divide its period
  GripHandParams hand;                  // the hand that holds the grip (common/hand/grip_hand.h)
  // The device holding the grip, as the registry names it (haptic_controller/device/device_registry.h): "grip" (the
  // built-in 8-string frame, common/spidar/grip_geometry.h) or "grip:FILE.json".
  std::string device = "grip";
  GripPose start;                       // where the grip starts, at rest, and the target holds until moved
  // A directory (which must exist) for the nodes' logs, world.csv and haptic.csv (the grip's centre as the finger,
  // the proxy's as the proxy), as a trial writes them: `viewer --replay` plays them back with the summary.json written
  // beside them. "": no logs.
  std::string out_dir;
};

// One tick, read after it.
struct ToolTick {
  double time_s = 0.0;
  GripPose target;  // the hand's target at the tick's end
  GripPose grip;    // as the driver measured it from the counts (the last good pose if this reading gave none)
  GripPose hand;    // where the simulated hand truly holds the grip, when the counts were read
  GripPose proxy;   // the tool proxy's grip pose
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();    // on the grip, as the servo commanded it
  Eigen::Vector3d torque_Nm = Eigen::Vector3d::Zero();  // on the grip, about its centre
  Eigen::Vector3d strings_force_N = Eigen::Vector3d::Zero();    // what the eight tensions put on the grip
  Eigen::Vector3d strings_torque_Nm = Eigen::Vector3d::Zero();
  int active = 0;  // contacts pushing the tool
};

// One scene object after the world's last step.
struct ToolLoopObject {
  BodyPose pose;
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();     // applied by the coupling since the start
  Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();
};

class ToolLoop {
 public:
  // Loads the scene (SceneError) and builds the world, servo, driver and device; std::invalid_argument for a scene
  // without a tool, position coupling, a world period that is not a whole number of ticks, or a start the device's
  // strings cannot hold (naming which).
  explicit ToolLoop(const ToolLoopOptions& options);
  ~ToolLoop();
  ToolLoop(const ToolLoop&) = delete;
  ToolLoop& operator=(const ToolLoop&) = delete;

  // The target pose at the end of the next tick (the hand aims along a straight line to it and holds); throws
  // std::invalid_argument for a pose that is not finite, or a position outside the device's frame.
  void set_target(const GripPose& target);
  // Takes `count` ticks. `targets`, if not empty, holds count poses: the target at the end of tick i. `out`, if not
  // empty, receives count records. Throws std::logic_error after finish(), std::invalid_argument for spans of the
  // wrong size or a bad target (before any tick).
  void step(std::uint64_t count, std::span<const GripPose> targets, std::span<ToolTick> out);

  std::uint64_t ticks() const { return ticks_; }
  double tick_period_s() const;
  const std::vector<std::string>& object_names() const { return object_names_; }
  std::vector<ToolLoopObject> objects() const;

  // Ends the run: two more world steps apply the servo's last reports, then the sessions end. Returns a summary: the
  // ticks, the device's and the tool's counters, per object the impulse the tool rendered against what the world
  // applied ("ledger"), and the world and haptic nodes' halves of a trial's summary.json ("world", "haptic"). Later
  // calls return the same document.
  const nlohmann::json& finish();
  bool finished() const { return finished_; }

 private:
  struct Parts;
  void tick(ToolTick* out);
  void check_target(const GripPose& target) const;

  std::unique_ptr<Parts> parts_;
  std::vector<std::string> object_names_;
  std::uint64_t ticks_ = 0;
  bool finished_ = false;
  nlohmann::json summary_;
};

}  // namespace impetus
