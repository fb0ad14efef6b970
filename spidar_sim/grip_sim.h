// SPDX-License-Identifier: Apache-2.0
#pragma once
// One simulated 8-string grip SPIDAR session (common/spidar/grip_geometry.h): the eight motors and strings, and the
// hand holding the grip (common/hand/grip_hand.h), advanced one device tick at a time, as DeviceSim (device_sim.h)
// advances the 4-string device and its finger.
//
// Contract of tick(): the commanded tensions, each clamped to the motors' [tension_min_N, tension_max_N] (a string can
// only pull, and a motor only so hard), are held for dt_s (zero-order hold); within the tick the grip moves in the
// hand's sub-steps, the strings' wrench W(pose)·t taken again at each; the counts at the end of the tick are returned.
// The hand aims at the target pose the caller gives, moving with the given velocities over the tick, or at a scripted
// trajectory's position and orientation (trajectory.h), sampled at every sub-step. Time starts at 0 with the grip at
// rest at the start pose. No allocation after construction.

#include "common/hand/grip_hand.h"
#include "common/spidar/grip_strings.h"
#include "spidar_sim/trajectory.h"

#include <Eigen/Core>

#include <optional>
#include <string>

namespace impetus {

// Why `trajectory` cannot be played on a grip device of `geometry`, or "" if it can: a target where the grip would
// leave the frame's cube (its centre closer to a face than the grip's radius), where the strings cannot hold it.
// Names the time and the point.
std::string grip_trajectory_problem(const Trajectory& trajectory, const SpidarGripGeometry& geometry);
// The same for one target point (world frame, m): "" if the strings can hold the grip there. Allocates only for a
// message.
std::string grip_point_problem(const Eigen::Vector3d& point_m, const SpidarGripGeometry& geometry);

class GripSim {
 public:
  // Throws std::invalid_argument (from GripHand) if the hand's parameters or the start are unusable, or if the
  // geometry's tension limits are not 0 <= min <= max.
  GripSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, const GripPose& start);
  // Plays `trajectory`: the hand starts at rest at its start and aims at it. Throws as above, and TrajectoryError if
  // the trajectory leaves the frame (grip_trajectory_problem).
  GripSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, Trajectory trajectory);

  // Advances one tick of the trajectory's hand (the second constructor; std::logic_error otherwise).
  const GripCounts& tick(const GripTensions& commanded_N, double dt_s);
  // True once the trajectory's clock reaches its end (the target then holds still).
  bool finished() const { return trajectory_ && trajectory_time_s() >= trajectory_->duration_s(); }
  // Holds the trajectory for the next tick of dt_s: its clock stands still and the hand aims where it is now, as
  // DeviceSim::hold_trajectory (a real-time device waiting for a world to touch, device_node.h).
  void hold_trajectory(double dt_s) { trajectory_start_s_ += dt_s; }
  // Session time less the time the trajectory was held.
  double trajectory_time_s() const { return time_s_ - trajectory_start_s_; }
  // Where the trajectory's hand aims now (the second constructor; the grip's pose otherwise).
  GripPose trajectory_target() const;

  // Advances one tick of dt_s (finite, > 0; else std::invalid_argument) and returns the encoder counts at its end.
  const GripCounts& tick(const GripTensions& commanded_N, const GripPose& target,
                         const Eigen::Vector3d& target_velocity_mps,
                         const Eigen::Vector3d& target_angular_velocity_radps, double dt_s);

  double time_s() const { return time_s_; }
  GripPose pose() const { return hand_.pose(); }
  const GripHand& hand() const { return hand_; }
  const GripStrings& strings() const { return strings_; }
  const GripCounts& encoder_counts() const { return counts_; }
  const GripTensions& tensions_N() const { return tensions_N_; }  // as applied: the command clamped
  // The strings' force and torque on the grip at the end of the last tick (N, N·m about its centre, world frame).
  GripWrench wrench() const;

 private:
  void apply(const GripTensions& commanded_N);  // clamped to the motors' range
  // One sub-step of h_s toward `aim`, the strings' wrench taken at the pose now.
  void substep(const GripPose& aim, const Eigen::Vector3d& aim_velocity_mps,
               const Eigen::Vector3d& aim_angular_velocity_radps, double h_s);

  GripStrings strings_;
  std::optional<Trajectory> trajectory_;
  GripHand hand_;
  GripTensions tensions_N_{};
  GripCounts counts_{};
  double time_s_ = 0.0;
  double trajectory_start_s_ = 0.0;  // session time of the trajectory's time 0 (hold_trajectory)
  std::size_t segment_hint_ = 0;  // the trajectory's segment of the last sub-step (Trajectory::sample_at)
};

}  // namespace impetus
