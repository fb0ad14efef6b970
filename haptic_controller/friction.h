// SPDX-License-Identifier: Apache-2.0
#pragma once
// Friction on the proxy (paper §6.2, docs/architecture.md §1.2 step 3).
//
// The proxy sticks to a material point of the touched object (the anchor), which moves with the object's velocity as
// sent by the world, v + ω × (anchor − com), while the spring force k(D − C) stays inside the static cone
// |f_t| ≤ μ_s·|f_n|. Outside it the proxy slides: it is placed back on the dynamic cone, |f_t| = μ_d·|f_n|, on the
// side of the anchor, and the anchor restarts there. Only the spring part of the force enters the cone test (the
// damper is a rendering filter, not a contact force), and since the spring is isotropic the test is purely geometric:
// the normal is the direction of the frictionless constraint displacement D₀ − C, |f_n| ∝ |D₀ − C|.
//
// Coefficients: the multiplier-weighted mean over the active planes (exact for one plane; a blend at edges and
// corners). In an infeasible pinch friction is off and the anchor is released.

#include <Eigen/Core>
#include <cstdint>

#include "haptic_controller/contact_plane.h"
#include "haptic_controller/proxy_projection.h"

namespace impetus {

struct FrictionAnchor {
  bool valid = false;  // false: no contact last tick, the next contact starts sticking where it lands
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  std::int32_t object_id = -1;  // the object the anchor moves with
};

struct FrictionResult {
  Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();
  bool sticking = false;
};

// `frictionless` is project_outside_planes(planes, finger). Updates `anchor`. Allocation-free.
FrictionResult apply_friction(const PlaneSet& planes, const ProxySolution& frictionless,
                              const Eigen::Vector3d& finger_m, double dt_s, FrictionAnchor& anchor);

}  // namespace impetus
