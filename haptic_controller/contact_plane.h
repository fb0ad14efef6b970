// SPDX-License-Identifier: Apache-2.0
#pragma once
// The planes the servo renders in one tick: paper §3.1's (point, normal) pairs after interpolation (§3.2), in Eigen
// form, plus the object data needed for friction (§6.2) and for sharing the reaction among objects (§3.4).
//
// A plane is a half-space constraint: the proxy must satisfy normal·(x − point_m) ≥ 0. Owned by the servo thread.

#include "common/contract/frames.h"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include <array>
#include <cstdint>
#include <cmath>
#include <limits>

namespace impetus {

struct ContactPlane {
  std::int32_t object_id = -1;
  std::uint32_t flags = 0;  // kPlaneDynamic etc., as sent by the world
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  double static_friction = 0.0;
  double dynamic_friction = 0.0;
  double extent_m = 0.0;  // how far from point_m the plane describes its object; 0: unbounded (link_types.h)
  // kPlaneBox, kPlaneCapsule: the body's axes (columns: body x, y, z in the world frame) and half sizes along them, m
  // (a capsule's: radius, radius, half length between its cap centres); its centre is com_m. Moved with the plane by
  // the interpolation and the local model (shape_planes.h).
  Eigen::Matrix3d box_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d box_half_m = Eigen::Vector3d::Zero();

  // How far from point_m the plane still describes its object (0: unbounded), for telling a plane whose object is
  // beside the finger from one it is in (proxy_projection.h). A sphere's and a box's is extent_m (its radius, its
  // diagonal). A capsule's and a cylinder's extent_m is their radius, which their planes are retaken with, but a
  // finger inside either may lie farther than that from the plane's point along the axis: theirs is the diagonal of
  // the cylinder that bounds them, as generous as a box's.
  double describes_within_m() const {
    if (capsule()) return std::hypot(2.0 * extent_m, 2.0 * (box_half_m.z() + extent_m));
    if (cylinder()) return std::hypot(2.0 * extent_m, 2.0 * box_half_m.z());
    return extent_m;
  }

  // Velocity of the object's material point at `x` (rigid body: v + ω × (x − com)).
  Eigen::Vector3d surface_velocity_mps(const Eigen::Vector3d& x_m) const {
    return velocity_mps + angular_velocity_radps.cross(x_m - com_m);
  }
  bool dynamic() const { return (flags & kPlaneDynamic) != 0; }
  bool sphere() const { return (flags & kPlaneSphere) != 0 && extent_m > 0.0; }
  bool box() const { return (flags & kPlaneBox) != 0 && (box_half_m.array() > 0.0).all(); }
  bool capsule() const { return (flags & kPlaneCapsule) != 0 && extent_m > 0.0; }
  bool cylinder() const { return (flags & kPlaneCylinder) != 0 && extent_m > 0.0 && box_half_m.z() > 0.0; }

  // Angular impulse about the CoM of `impulse_Ns` applied by a finger at `proxy_m`. On a flat face the push acts at
  // the proxy. On a sphere its normal part acts through the centre, so only the part along the surface (friction)
  // turns the ball, wherever on the tangent plane the proxy sits (an edge with another plane can hold it off the
  // tangent point, and a lever there would spin a ball pushed straight). On a capsule likewise through the axis point
  // under the plane's point (point − radius·normal), which may lie off the centre: a push near an end turns it.
  Eigen::Vector3d angular_impulse_Nms(const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& impulse_Ns) const {
    if (!sphere() && !capsule()) return (proxy_m - com_m).cross(impulse_Ns);
    const Eigen::Vector3d normal_part = impulse_Ns.dot(normal) * normal;
    const Eigen::Vector3d centre_m = point_m - extent_m * normal;
    return (centre_m - com_m).cross(normal_part) + (proxy_m - com_m).cross(impulse_Ns - normal_part);
  }
};

// Fixed-capacity set, filled in place each tick.
struct PlaneSet {
  std::array<ContactPlane, kMaxPlanes> planes{};
  std::uint32_t count = 0;
  // How far from the finger the planes describe the world (the frame's reach radius): the world sent every object
  // within it, so a proxy the planes place farther away may lie inside an object nobody sent (proxy_projection.h).
  double valid_within_m = std::numeric_limits<double>::infinity();
};

// Conversion of one world plane, unchanged.
ContactPlane to_contact_plane(const Plane& plane);

}  // namespace impetus
