// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 1 kHz servo of a tool endpoint (docs/tool.md): the point finger's servo (servo.h) with a rigid tool in place of
// the finger. Each tick:
//  1. the grip's pose from the device;
//  2. the planes of the objects near it, moved between world frames as the frame's coupling says (interpolated,
//     paper §3.2, or carried by the local model, §6.3);
//  3. the tool's 6-DoF god-object (tool_proxy.h) against their shapes;
//  4. the wrench on the grip, and its reaction shared per object, linear and angular impulse about each object's
//     centre of mass, accumulated tick by tick into the same report a finger's goes into (§3.4); the local model
//     moves the objects by this tick's shares.
//
// The world sends the planes of the objects within its reach of the report's proxy point, which is the tool proxy's
// grip centre; the scene's reach radius (haptic.reach_radius_m) must cover the tool about that centre
// (ToolContacts::bounding_radius_m) for every object the tool can touch to arrive.
//
// Threading: one servo thread owns it. Real time: the constructor preallocates; on_plane_frame and tick never
// allocate, lock, block or throw.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/local_dynamics.h"
#include "haptic_controller/plane_motion.h"
#include "haptic_controller/tool/tool_proxy.h"

#include <cstdint>

namespace impetus {

struct ToolTickResult {
  BodyPose grip;   // the last valid grip pose
  BodyPose proxy;  // the proxy's grip pose
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();    // on the grip
  Eigen::Vector3d torque_Nm = Eigen::Vector3d::Zero();  // on the grip, about its centre
  bool render = false;       // command the wrench; false: the device's minimum output (no grip, or a fault)
  bool grip_valid = false;   // the device gave a valid pose this tick
  bool world_stale = false;  // the newest world frame is stale (common/runtime/staleness.h): its planes hold
  int active = 0;            // contacts pushing the tool
  double interpolation_weight = 1.0;
};

class ToolServo {
 public:
  // Serves endpoint `endpoint` of `haptic_session` with the tool `tool` held by the coupling `coupling`; throws
  // std::invalid_argument for an unusable tool or coupling (ToolProxy).
  ToolServo(const ToolShape& tool, const ToolCoupling& coupling, std::uint64_t haptic_session, EndpointId endpoint = 0);

  // A validated world frame arrived at servo time now_s. Frames of a new world session restart the planes' motion.
  void on_plane_frame(const PlaneFrame& frame, double now_s);
  // One tick at servo time now_s, dt_s after the last. grip == nullptr, or a pose that is not finite, means no device
  // (or a fault): minimum output, nothing accumulated, and the proxy starts again at the grip when it comes back.
  const ToolTickResult& tick(const BodyPose* grip, double now_s, double dt_s);

  const HapticReport& report() const { return accumulator_.report(); }
  const ImpulseAccumulator& accumulator() const { return accumulator_; }
  const ToolProxy& proxy() const { return proxy_; }
  const PlaneSet& planes() const { return planes_; }  // the planes of the last tick
  const ToolTickResult& last_result() const { return result_; }
  bool has_world() const { return have_frame_; }  // a world frame has reached it
  std::uint64_t ticks() const { return ticks_; }
  std::uint64_t faults() const { return faults_; }

 private:
  void idle();
  // Bounds what each object the frame moves may hold the proxy inside (tool_proxy.h hold_overlaps).
  void limit_holds(const PlaneFrame& frame);

  PlaneFrame current_frame_{};
  bool have_frame_ = false;
  double frame_arrival_s_ = 0.0;
  PlaneSet planes_{};
  InterpolatedPlanes interpolated_;
  LocalDynamics local_;
  PlaneMotion* motion_ = &interpolated_;
  ToolProxy proxy_;
  ImpulseAccumulator accumulator_;
  bool grip_known_ = false;
  ToolTickResult result_{};
  std::uint64_t ticks_ = 0;
  std::uint64_t faults_ = 0;
};

}  // namespace impetus
