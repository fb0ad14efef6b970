// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 8-string grip SPIDAR's driver (docs/devices.md §8): the two halves a tool endpoint needs of the device, each
// tested alone and joined here —
//   GripKinematics              encoder counts → the grip's pose, warm-started from the last pose;
//   distribute_grip_tension     the wrench on the grip → eight tensions within the motors, at the pose read last.
// What carries the counts in and the tensions out (a device port, or a simulated device in the same process) is the
// caller's.
//
// A reading whose pose the strings do not give (grip_kinematics.h: not finite, singular, not converged, inconsistent)
// is no pose: read() returns nullptr, counts it, and the next reading starts again from the last good pose. Owned by
// the servo thread; allocation-free and no exceptions after construction.

#include "haptic_controller/device/grip_kinematics.h"
#include "haptic_controller/device/grip_tension.h"

#include <cstdint>

namespace impetus {

struct GripDriverCounters {
  std::uint64_t readings = 0;
  std::uint64_t bad_readings = 0;  // counts that gave no pose
  std::uint64_t saturations = 0;   // wrenches scaled down to what the motors can render
  std::uint64_t no_closure = 0;    // poses where no tension balance holds the grip (every string at t_min)
  int most_iterations = 0;         // Gauss–Newton's, over the readings
};

class GripDriver {
 public:
  // `start` is the first guess of the pose (the frame's centre will do: a cold start converges across the working
  // volume, grip_kinematics.h).
  GripDriver(const SpidarGripGeometry& geometry, const GripPose& start);

  // The grip's pose from `counts`, or nullptr (and status() says why).
  const GripPose* read(const GripCounts& counts);
  // The tensions that put `wrench` (force, torque about the grip's centre; world frame) on the grip at the pose read
  // last; with `render` false, or before any pose, every string at the motors' minimum (taut, no wrench to speak of).
  const GripTensions& command(const GripWrench& wrench, bool render);

  const GripSolve& status() const { return solve_; }
  const GripTensionSolution& tension() const { return tension_; }
  const GripDriverCounters& counters() const { return counters_; }
  const GripKinematics& kinematics() const { return kinematics_; }

 private:
  GripKinematics kinematics_;
  GripPose pose_;   // the last good pose (the next reading's guess)
  GripPose found_;  // the last solve's answer
  bool have_pose_ = false;
  GripSolve solve_{};
  GripTensionSolution tension_{};
  GripTensions tensions_N_{};
  GripDriverCounters counters_{};
};

}  // namespace impetus
