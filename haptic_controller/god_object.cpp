#include "haptic_controller/god_object.h"

namespace impetus {

const GodObjectResult& GodObject::solve(const PlaneSet& planes, const Eigen::Vector3d& finger_m, double dt_s) {
  result_.contact = project_outside_planes(planes, finger_m);
  const FrictionResult friction = apply_friction(planes, result_.contact, finger_m, dt_s, anchor_);
  result_.contact.proxy_m = friction.proxy_m;
  result_.sticking = friction.sticking;
  return result_;
}

void GodObject::reset() {
  anchor_ = FrictionAnchor{};
  result_ = GodObjectResult{};
}

}  // namespace impetus
