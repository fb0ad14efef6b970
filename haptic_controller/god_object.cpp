// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/god_object.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// An object whose surface moves toward the finger faster than this is arriving, not resting: ODE's resting contacts
// jitter by micrometres per second, anything moving a millimetre per second is being driven into the finger.
constexpr double kRestingSpeed_mps = 1e-3;

// Signed distance of the finger in front of a plane (negative: behind it, inside the object).
double clearance_m(const ContactPlane& plane, const Eigen::Vector3d& finger_m) {
  return plane.normal.dot(finger_m - plane.point_m);
}

}  // namespace

const PlaneSet& GodObject::armed_planes(const PlaneSet& planes, const Eigen::Vector3d& finger_m) {
  if (session_starting_ && planes.count > 0) {
    session_starting_ = false;
    for (std::uint32_t k = 0; k < planes.count && sunk_count_ < static_cast<int>(kMaxServoPlanes); ++k) {
      // Only a resting object is set back: one that moves onto the finger pushes it out like any moving plane.
      const ContactPlane& plane = planes.planes[k];
      const double approach_mps = plane.surface_velocity_mps(plane.point_m).dot(plane.normal);
      const double depth_m = -clearance_m(plane, finger_m);
      if (depth_m <= 0.0 || clearance_m(plane, session_start_finger_m_) >= 0.0 || approach_mps > kRestingSpeed_mps) {
        continue;
      }
      bool listed = false;
      for (int d = 0; d < sunk_count_; ++d) listed = listed || sunk_[d].object_id == plane.object_id;
      if (listed) continue;
      const double held_m = held_depth_m(plane.object_id);
      // Set back by what the finger sank meanwhile; an object it was not in (held depth −∞) is disarmed.
      const double setback_m = depth_m - held_m;
      if (setback_m > 0.0) sunk_[sunk_count_++] = Sunk{plane.object_id, setback_m, depth_m};
    }
    held_count_ = 0;
  }
  if (sunk_count_ == 0) return planes;

  // Restore what the finger has left (or what left the frame); keep the rest, and how deep the finger is in it.
  int kept = 0;
  for (int d = 0; d < sunk_count_; ++d) {
    double depth_m = 0.0;
    for (std::uint32_t k = 0; k < planes.count; ++k) {
      const ContactPlane& plane = planes.planes[k];
      if (plane.object_id == sunk_[d].object_id) depth_m = std::max(depth_m, -clearance_m(plane, finger_m));
    }
    if (depth_m > 0.0) {
      sunk_[kept] = sunk_[d];
      sunk_[kept++].depth_m = depth_m;
    }
  }
  sunk_count_ = kept;
  if (sunk_count_ == 0) return planes;

  armed_.count = 0;
  armed_.valid_within_m = planes.valid_within_m;
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    double setback_m = 0.0;
    for (int d = 0; d < sunk_count_; ++d) {
      if (planes.planes[k].object_id == sunk_[d].object_id) setback_m = sunk_[d].setback_m;
    }
    if (std::isinf(setback_m)) continue;  // disarmed
    armed_index_[armed_.count] = static_cast<int>(k);
    ContactPlane& armed = armed_.planes[armed_.count++];
    armed = planes.planes[k];
    armed.point_m -= armed.normal * setback_m;
  }
  return armed_;
}

const GodObjectResult& GodObject::solve(const PlaneSet& planes, const Eigen::Vector3d& finger_m, double dt_s,
                                        const MeshHold* walked) {
  const PlaneSet& armed = armed_planes(planes, finger_m);
  result_.contact = project_outside_planes(armed, finger_m);
  const FrictionResult friction = apply_friction(armed, result_.contact, finger_m, dt_s, anchor_);
  // The move from a point outside every mesh stops where it would go into one. Less than the surface tolerance cannot
  // go in deeper than that (and is what the frictionless proxy differs from the walk's end by, in rounding).
  const bool from_walk = walked != nullptr && walked->walked;
  const Eigen::Vector3d& from_m = from_walk ? walked->end_m : result_.contact.proxy_m;
  result_.contact.proxy_m = (friction.proxy_m - from_m).squaredNorm() > kOnSurface_m * kOnSurface_m
                                ? stop_at_meshes(armed, from_m, friction.proxy_m, from_walk ? walked : nullptr)
                                : friction.proxy_m;
  if (anchor_.valid) anchor_.point_m = result_.contact.proxy_m;
  result_.sticking = friction.sticking;
  // What the finger presses and how deep: what end_finger_session keeps if the finger vanishes after this tick.
  pressed_count_ = 0;
  for (int j = 0; j < listed_constraints(result_.contact); ++j) {
    const int index = result_.contact.active[j].plane;
    if (index < 0) continue;
    const ContactPlane& plane = armed.planes[index];
    pressed_[pressed_count_++] = Pressed{plane.object_id, std::max(0.0, -clearance_m(plane, finger_m))};
  }
  if (&armed != &planes) {
    // The caller shares the reaction by indices into its own PlaneSet.
    for (int j = 0; j < result_.contact.active_count; ++j) {  // a pinch's conflicting plane is counted
      int& index = result_.contact.active[j].plane;
      if (index >= 0) index = armed_index_[index];
    }
  }
  return result_;
}

double GodObject::held_depth_m(std::int32_t object_id) const {
  double depth_m = -std::numeric_limits<double>::infinity();
  for (int h = 0; h < held_count_; ++h) {
    if (held_[h].object_id == object_id) depth_m = std::max(depth_m, held_[h].depth_m);
  }
  return depth_m;
}

void GodObject::reset() {
  forget_contact();
  held_count_ = 0;
}

void GodObject::end_finger_session() {
  // What the finger pressed, and the objects it is set back from: how deep it is behind their set-back planes (less
  // than zero when it has room before pressing, −∞ when disarmed), so a session to come carries the setback on.
  held_count_ = 0;
  for (int p = 0; p < pressed_count_; ++p) held_[held_count_++] = pressed_[p];
  for (int d = 0; d < sunk_count_; ++d) {
    held_[held_count_++] = Pressed{sunk_[d].object_id, sunk_[d].depth_m - sunk_[d].setback_m};
  }
  forget_contact();
}

void GodObject::begin_finger_session(const Eigen::Vector3d& finger_m) {
  forget_contact();  // what the last session held, if it ended, is kept for armed_planes at the first solve
  session_starting_ = true;
  session_start_finger_m_ = finger_m;
}

void GodObject::forget_contact() {
  anchor_ = FrictionAnchor{};
  result_ = GodObjectResult{};
  pressed_count_ = 0;
  sunk_count_ = 0;
  session_starting_ = false;
}

}  // namespace impetus
