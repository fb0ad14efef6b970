// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/tool/tool_servo.h"

#include "common/runtime/staleness.h"
#include "haptic_controller/plane_interpolator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {

ToolServo::ToolServo(const ToolShape& tool, const ToolCoupling& coupling, std::uint64_t haptic_session,
                     EndpointId endpoint)
    : local_(haptic_session), proxy_(tool, coupling), accumulator_(haptic_session, endpoint) {}

void ToolServo::on_plane_frame(const PlaneFrame& frame, double now_s) {
  const bool continues = have_frame_ && frame.world_session == current_frame_.world_session;
  motion_ = frame.coupling == Coupling::local ? static_cast<PlaneMotion*>(&local_) : &interpolated_;
  // A local frame restarts the objects from the world's state, which may put them where the model did not: the proxy
  // is held inside what it then overlaps and let out over the period, not thrown out (tool_proxy.h). A new world may
  // put them anywhere: held until the tool leaves.
  if (!continues) {
    proxy_.hold_overlaps(std::numeric_limits<double>::infinity());
  } else if (frame.coupling == Coupling::local) {
    proxy_.hold_overlaps(frame.world_period_s);
    limit_holds(frame);
  }
  motion_->on_frame(continues ? current_frame_ : frame, frame, continues ? &planes_ : nullptr,
                    result_.proxy.position_m);
  copy_used(frame, current_frame_);
  have_frame_ = true;
  frame_arrival_s_ = now_s;
  accumulator_.on_plane_frame(frame);
}

void ToolServo::limit_holds(const PlaneFrame& frame) {
  // Only the world's correction of the model is held, not the motion the model had already shown (an object that
  // settles onto the tool under its weight must still be held up): per object, the most the jump from the pose the
  // tool was meeting (the last tick's plane) to the frame's moved any of its points, |δx| + |δθ|·r with r the
  // farthest point of its shape from its centre.
  for (std::uint32_t k = 0; k < frame.plane_count && k < kMaxServoPlanes; ++k) {
    const ContactPlane now = to_contact_plane(frame.planes[k]);
    for (std::uint32_t d = 0; d < planes_.count; ++d) {
      const ContactPlane& shown = planes_.planes[d];
      if (shown.object_id != now.object_id) continue;
      const BodyPose a = object_pose(shown), b = object_pose(now);
      const Eigen::AlignedBox3d bounds = world_bounds(now.shape, BodyPose{});
      const double radius_m = std::max(bounds.min().norm(), bounds.max().norm());
      proxy_.limit_hold(now.object_id, (b.position_m - a.position_m).norm() +
                                           a.orientation.angularDistance(b.orientation) * radius_m);
      break;
    }
  }
}

void ToolServo::idle() {
  grip_known_ = false;
  result_.force_N.setZero();
  result_.torque_Nm.setZero();
  result_.render = false;
  result_.active = 0;
  HapticReport& report = accumulator_.report();
  report.finger_valid = 0;
  report.finger_velocity_mps = {};
  report.force_N = {};
  report.torque_Nm = {};
}

const ToolTickResult& ToolServo::tick(const BodyPose* grip, double now_s, double dt_s) {
  ++ticks_;
  HapticReport& report = accumulator_.report();
  report.tick = ticks_;
  report.haptic_time_s = now_s;
  local_.note_tick(ticks_);

  // 1. The grip.
  const bool valid = grip != nullptr && grip->position_m.allFinite() && grip->orientation.coeffs().allFinite() &&
                     grip->orientation.norm() > 0.0;
  result_.grip_valid = valid;
  if (!valid) {
    if (grip != nullptr) ++faults_;
    idle();
    return result_;
  }
  const BodyPose pose{grip->position_m, grip->orientation.normalized()};
  const Eigen::Vector3d velocity_mps =
      grip_known_ && dt_s > 0.0 ? Eigen::Vector3d((pose.position_m - result_.grip.position_m) / dt_s)
                                : Eigen::Vector3d::Zero();
  if (!grip_known_) proxy_.reset(pose);  // a grip that appears inside an object is not thrown out (tool_proxy.h)
  grip_known_ = true;
  result_.grip = pose;

  // 2. The planes, between world frames (§3.2, §6.3); a stale world keeps its last (w = 1).
  double w = 1.0;
  result_.world_stale = false;
  if (have_frame_) {
    w = interpolation_weight(now_s, frame_arrival_s_, current_frame_.world_period_s);
    result_.world_stale = world_stale(now_s - frame_arrival_s_, current_frame_.world_period_s);
    motion_->planes_for_tick(w, dt_s, result_.world_stale, result_.proxy.position_m, planes_);
  } else {
    planes_.count = 0;
  }
  result_.interpolation_weight = w;

  // 3. The tool's proxy and the wrench on the grip.
  const ToolResult& solved = proxy_.solve(planes_, pose, dt_s);
  if (solved.fault) {
    ++faults_;
    idle();
    return result_;
  }
  result_.proxy = solved.proxy;
  result_.force_N = solved.force_N;
  result_.torque_Nm = solved.torque_Nm;
  result_.active = solved.active;
  result_.render = true;

  // 4. The report: where the tool is (its grip as the finger, its proxy as the proxy: the world's reach is taken
  //    about it), and the reaction per object; the local model moves the objects by it.
  report.finger_m = to_vec3(pose.position_m);
  report.proxy_m = to_vec3(solved.proxy.position_m);
  report.finger_velocity_mps = to_vec3(velocity_mps);
  report.finger_valid = 1;
  report.force_N = to_vec3(solved.force_N);
  report.torque_Nm = to_vec3(solved.torque_Nm);
  const auto wxyz = [](const Eigen::Quaterniond& q) { return std::array<double, 4>{q.w(), q.x(), q.y(), q.z()}; };
  report.oriented = 1;
  report.finger_wxyz = wxyz(pose.orientation);
  report.proxy_wxyz = wxyz(solved.proxy.orientation);
  accumulator_.add_shares(proxy_.shares(), proxy_.share_count(), ticks_);
  if (have_frame_) motion_->take_shares(accumulator_.last_shares(), accumulator_.last_share_count());
  return result_;
}

}  // namespace impetus
