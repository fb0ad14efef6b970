// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/friction.h"

#include <cmath>

namespace impetus {
namespace {

// Below this penetration the contact has no normal force worth a cone (and no reliable normal direction).
constexpr double kMinFrictionDepth_m = 1e-12;

const ContactPlane* find_object(const PlaneSet& planes, std::int32_t object_id) {
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    if (planes.planes[k].object_id == object_id) return &planes.planes[k];
  }
  return nullptr;
}

// A point on the active surfaces and outside every plane.
Eigen::Vector3d onto_surface(const PlaneSet& planes, const ProxySolution& frictionless, const Eigen::Vector3d& x_m) {
  return project_outside_planes(planes, project_onto_active(planes, frictionless, x_m)).proxy_m;
}

}  // namespace

FrictionResult apply_friction(const PlaneSet& planes, const ProxySolution& frictionless,
                              const Eigen::Vector3d& finger_m, double dt_s, FrictionAnchor& anchor) {
  const Eigen::Vector3d constraint = frictionless.proxy_m - finger_m;  // D₀ − C
  const double depth_m = constraint.norm();
  if (frictionless.active_count == 0 || frictionless.infeasible || !(depth_m > kMinFrictionDepth_m)) {
    anchor.valid = false;
    return {frictionless.proxy_m, false};
  }

  double weight_sum = 0.0, mu_static = 0.0, mu_dynamic = 0.0, heaviest = -1.0;
  std::int32_t owner = -1;
  for (int j = 0; j < frictionless.active_count; ++j) {
    const ContactPlane& plane = planes.planes[frictionless.active[j].plane];
    const double lambda = frictionless.active[j].multiplier_m;
    weight_sum += lambda;
    mu_static += lambda * plane.static_friction;
    mu_dynamic += lambda * plane.dynamic_friction;
    if (lambda > heaviest) {
      heaviest = lambda;
      owner = plane.object_id;
    }
  }
  if (!(weight_sum > 0.0)) {
    anchor.valid = false;
    return {frictionless.proxy_m, false};
  }
  mu_static /= weight_sum;
  mu_dynamic /= weight_sum;

  // Where the anchor's material point is now; a fresh contact anchors where the finger's projection lands.
  Eigen::Vector3d carried = frictionless.proxy_m;
  if (anchor.valid) {
    carried = anchor.point_m;
    if (const ContactPlane* object = find_object(planes, anchor.object_id); object && std::isfinite(dt_s)) {
      carried += object->surface_velocity_mps(anchor.point_m) * dt_s;
    }
  }
  const Eigen::Vector3d stuck = onto_surface(planes, frictionless, carried);

  const Eigen::Vector3d normal = constraint / depth_m;
  const Eigen::Vector3d spring = stuck - finger_m;  // ∝ the spring force if the proxy stays stuck
  const double spring_normal = spring.dot(normal);
  const Eigen::Vector3d spring_tangent = spring - spring_normal * normal;
  const double tangent_m = spring_tangent.norm();

  FrictionResult result;
  if (spring_normal > 0.0 && tangent_m <= mu_static * spring_normal) {
    result = {stuck, true};
  } else {
    // Slide back onto the dynamic cone, toward the anchor: |f_t| = μ_d·|f_n| with |f_n| = k·depth.
    const Eigen::Vector3d direction =
        tangent_m > 0.0 ? Eigen::Vector3d(spring_tangent / tangent_m) : Eigen::Vector3d::Zero();
    result = {onto_surface(planes, frictionless, frictionless.proxy_m + direction * (mu_dynamic * depth_m)), false};
  }
  if (!result.proxy_m.allFinite()) {  // cannot happen for finite planes; never hand NaN on
    anchor.valid = false;
    return {frictionless.proxy_m, false};
  }
  anchor = {true, result.proxy_m, owner};
  return result;
}

}  // namespace impetus
