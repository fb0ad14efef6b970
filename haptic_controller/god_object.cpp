// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/god_object.h"

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
    for (std::uint32_t k = 0; k < planes.count && disarmed_count_ < static_cast<int>(kMaxPlanes); ++k) {
      // Only a resting object is disarmed: one that moves onto the finger pushes it out like any moving plane.
      const ContactPlane& plane = planes.planes[k];
      const double approach_mps = plane.surface_velocity_mps(plane.point_m).dot(plane.normal);
      if (clearance_m(plane, finger_m) < 0.0 && clearance_m(plane, session_start_finger_m_) < 0.0 &&
          approach_mps <= kRestingSpeed_mps) {
        disarmed_ids_[disarmed_count_++] = plane.object_id;
      }
    }
  }
  if (disarmed_count_ == 0) return planes;

  // Re-arm what the finger has left (or what left the frame); keep the rest disarmed.
  int kept = 0;
  for (int d = 0; d < disarmed_count_; ++d) {
    bool still_inside = false;
    for (std::uint32_t k = 0; k < planes.count; ++k) {
      const ContactPlane& plane = planes.planes[k];
      if (plane.object_id == disarmed_ids_[d] && clearance_m(plane, finger_m) < 0.0) still_inside = true;
    }
    if (still_inside) disarmed_ids_[kept++] = disarmed_ids_[d];
  }
  disarmed_count_ = kept;
  if (disarmed_count_ == 0) return planes;

  armed_.count = 0;
  armed_.valid_within_m = planes.valid_within_m;
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    bool disarmed = false;
    for (int d = 0; d < disarmed_count_; ++d) disarmed = disarmed || planes.planes[k].object_id == disarmed_ids_[d];
    if (disarmed) continue;
    armed_index_[armed_.count] = static_cast<int>(k);
    armed_.planes[armed_.count++] = planes.planes[k];
  }
  return armed_;
}

const GodObjectResult& GodObject::solve(const PlaneSet& planes, const Eigen::Vector3d& finger_m, double dt_s) {
  const PlaneSet& armed = armed_planes(planes, finger_m);
  result_.contact = project_outside_planes(armed, finger_m);
  const FrictionResult friction = apply_friction(armed, result_.contact, finger_m, dt_s, anchor_);
  result_.contact.proxy_m = friction.proxy_m;
  result_.sticking = friction.sticking;
  if (&armed != &planes) {
    // The caller shares the reaction by indices into its own PlaneSet.
    for (int j = 0; j < result_.contact.active_count; ++j) {  // a pinch's conflicting plane is counted
      int& index = result_.contact.active[j].plane;
      if (index >= 0) index = armed_index_[index];
    }
  }
  return result_;
}

void GodObject::reset() {
  anchor_ = FrictionAnchor{};
  result_ = GodObjectResult{};
  disarmed_count_ = 0;
  session_starting_ = false;
}

void GodObject::begin_finger_session(const Eigen::Vector3d& finger_m) {
  reset();
  session_starting_ = true;
  session_start_finger_m_ = finger_m;
}

}  // namespace impetus
