// SPDX-License-Identifier: Apache-2.0
#pragma once
// A closed loop: the in-process trial (in_process_trial.h) advanced tick by tick by its caller, who moves each
// finger's target (or pushes with the hand) between ticks and reads back what the servo rendered and where the objects
// are. A controller, a learned policy or a model of a person drives the finger instead of a scripted trajectory; the
// nodes, links and lockstep schedule are the trial's own (loop/in_process_rig.h), so the physics is the same: steering
// the targets to a trajectory's own points replays that trajectory's trial bitwise (DeviceSim::steer says how).
//
// Time: tick t is at t·T (T = tick_period_s(), 1 ms); the world steps at ticks i·n + phase as in every lockstep run.
// The device's clock is the running sum of T, so a trajectory is replayed at time_s() + T after each tick.
// Frames: the world frame, SI units. Not thread-safe; one Simulation is stepped from one thread at a time.

#include "common/contract/vec3.h"
#include "loop/in_process_trial.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace impetus {

class InProcessRig;

// One finger of the closed loop: its name and where its target (and the finger, at rest) starts.
struct SimulationFinger {
  std::string name;
  Vec3 start_m{};
};

struct SimulationOptions {
  // Scene, coupling, rates, contact spring, link delay and log directory, as a scripted trial takes them; its
  // trajectory, fingers, finger_paths, followers and duration_s must be left empty (the caller moves the fingers and
  // says when the run ends).
  InProcessTrialOptions trial;
  std::vector<SimulationFinger> fingers;  // 1 to kMaxFingers; finger k is endpoint k of the world
};

// One finger in one tick, read after the tick.
struct FingerTick {
  double time_s = 0.0;          // the tick's time t·T
  Vec3 target_m{};              // the hand's target at the tick's end
  Vec3 finger_m{};              // the fingertip as the device measured it (the servo's C_j)
  Vec3 finger_velocity_mps{};   // the fingertip's true velocity (the simulated hand's)
  Vec3 proxy_m{};               // the god-object D_j
  Vec3 force_N{};               // on the finger, as commanded to the device
  Vec3 object_impulse_Ns{};     // running total of the reaction this finger gave the objects
  std::int32_t active_planes = 0;  // constraints holding the proxy: 0 free, 1 face, 2 edge, 3 corner
};

// One scene object after the world's last step (static objects never change).
struct SimulationObject {
  Vec3 position_m{};              // centre of mass
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};  // body → world, unit
  Vec3 velocity_mps{};
  Vec3 angular_velocity_radps{};  // world frame
  Vec3 impulse_Ns{};              // the total the world applied through the couplings since the start
};

class Simulation {
 public:
  // Builds the nodes; throws std::invalid_argument for an option out of range (naming it) and SceneError for a bad
  // scene, as run_in_process_trial does.
  explicit Simulation(const SimulationOptions& options);
  ~Simulation();  // finishes the run if finish() was not called
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  std::size_t finger_count() const { return finger_count_; }
  const std::vector<std::string>& object_names() const { return object_names_; }
  double tick_period_s() const;
  std::uint64_t ticks() const { return ticks_; }  // ticks taken so far
  double device_time_s() const;                   // the device's clock: the running sum of T over the ticks
  bool finished() const { return finished_; }
  // The world's start-up warnings (WorldNode::warnings): objects placed inside each other, too light to couple.
  std::vector<std::string> warnings() const;

  // Where finger k's target is at the end of the next tick (it moves there in a straight line and holds); throws
  // std::invalid_argument for k out of range or a point that is not finite.
  void set_target(std::size_t finger, const Vec3& target_m);
  // A force the hand adds on finger k from the next tick on, on top of its pull toward the target (N).
  void set_hand_force(std::size_t finger, const Vec3& force_N);

  // Takes `count` ticks. `targets`, if not empty, holds count × finger_count() points (tick-major): finger k's target
  // at the end of tick i is targets[i·finger_count() + k]. `out`, if not empty, receives count × finger_count()
  // records the same way. Returns the ticks taken: fewer than `count` only when a stop was requested (options.stop).
  // Throws std::logic_error after finish() and std::invalid_argument for arrays of the wrong size or a target that is
  // not finite (before any tick is taken).
  std::uint64_t step(std::uint64_t count, std::span<const Vec3> targets, std::span<FingerTick> out);

  // Every scene object now, in scene order (object_names()).
  std::vector<SimulationObject> objects() const;

  // Ends the run: the world and device sessions close, the logs are flushed. Returns summary.json's document, as a
  // scripted trial's. Later calls return the same document.
  const nlohmann::json& finish();

 private:
  void check_finger(std::size_t finger) const;  // std::invalid_argument unless finger < finger_count()

  std::unique_ptr<InProcessRig> rig_;
  std::size_t finger_count_ = 0;
  std::vector<std::string> object_names_;
  std::uint64_t ticks_ = 0;
  bool finished_ = false;
  nlohmann::json summary_;
};

}  // namespace impetus
