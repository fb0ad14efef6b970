#pragma once
// The god-object (Zilles & Salisbury; paper §3.3, DESIGN.md §1 haptic tick step 3): the proxy D_j, the point that
// represents the finger on the surface, outside every interpolated plane, with friction (paper §6.2).
//
// GodObject::solve = project_outside_planes (the frictionless proxy and the contact's multipliers) followed by
// apply_friction (stick/slip of the proxy on the surface). The reported active constraints and multipliers are the
// frictionless ones: the normal load each plane carries, by which the reaction is shared among objects (§3.4).
// Owned by the servo thread; allocation-free.

#include "haptic_controller/contact_plane.h"
#include "haptic_controller/friction.h"
#include "haptic_controller/proxy_projection.h"

#include <Eigen/Core>

namespace impetus {

struct GodObjectResult {
  ProxySolution contact;  // contact.proxy_m is the final proxy D_j (after friction)
  bool sticking = false;
};

class GodObject {
 public:
  // `dt_s` is the real time since the previous solve: how far the anchor's object moved.
  const GodObjectResult& solve(const PlaneSet& planes, const Eigen::Vector3d& finger_m, double dt_s);

  // No contact memory (device detached, session restart).
  void reset();

  const GodObjectResult& result() const { return result_; }

 private:
  FrictionAnchor anchor_;
  GodObjectResult result_;
};

}  // namespace impetus
