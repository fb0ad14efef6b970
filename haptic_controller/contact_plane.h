// SPDX-License-Identifier: Apache-2.0
#pragma once
// The planes the servo renders in one tick: paper §3.1's (point, normal) pairs after interpolation (§3.2), in Eigen
// form, plus the object data needed for friction (§6.2) and for sharing the reaction among objects (§3.4).
//
// A plane is a half-space constraint: the proxy must satisfy normal·(x − point_m) ≥ 0. Owned by the servo thread.

#include "common/contract/frames.h"
#include "common/shape/shape.h"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include <array>
#include <cstdint>
#include <cmath>
#include <limits>

namespace impetus {

// The plane itself (point, normal), its body's centre and axes and its shape (common/shape/shape.h ShapePlane): what
// the shape module retakes every tick; plus what friction and the sharing of the reaction need.
struct ContactPlane : ShapePlane {
  std::int32_t object_id = -1;
  std::uint32_t flags = 0;  // kPlaneDynamic, kPlaneDeformable, as sent by the world
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  double static_friction = 0.0;
  double dynamic_friction = 0.0;
  double extent_m = 0.0;  // how far from point_m the plane describes its object; 0: unbounded (Plane::extent_m)
  // A deformable surface's yield (Plane::yield_force_N, yield_depth_mpNs, yield_radius_m, yield_room_m,
  // yield_compliance_mpN); zero for the rigid.
  double yield_force_N = 0.0;
  double yield_depth_mpNs = 0.0;
  double yield_radius_m = 0.0;
  double yield_room_m = 0.0;
  double yield_compliance_mpN = 0.0;
  // A mesh triangle the god-object's walk met on the proxy's way this tick (mesh_walk.h): the surface itself, not a
  // first-order picture of it, so it holds the proxy however far from its point the finger is (no extent).
  bool met = false;

  // Whether the plane carries its body's shape (the floor's does not).
  bool shaped() const { return shape.kind != ShapeKind::none; }
  const ShapeTraits& shape_traits() const { return traits(shape.kind); }

  // How far from point_m the plane still describes its object (0: unbounded), for telling a plane whose object is
  // beside the finger from one it is in (proxy_projection.h): the shape's (common/shape/shape.h describes_within_m).
  double describes_within_m() const {
    if (met) return 0.0;
    return shaped() ? impetus::describes_within_m(shape) : extent_m;
  }

  // Velocity of the object's material point at `x` (rigid body: v + ω × (x − com)).
  Eigen::Vector3d surface_velocity_mps(const Eigen::Vector3d& x_m) const {
    return velocity_mps + angular_velocity_radps.cross(x_m - com_m);
  }
  bool dynamic() const { return (flags & kPlaneDynamic) != 0; }
  bool deformable() const { return (flags & kPlaneDeformable) != 0; }

  // Angular impulse about the CoM of `impulse_Ns` applied by a finger at `proxy_m`. On a flat face the push acts at
  // the proxy. Where a push along the normal passes through the body's core (ShapeTraits::normal_through_core: a
  // ball, a rod with round ends) its normal part acts at the core point under the plane's point (point −
  // radius·normal): only the part along the surface (friction) turns a ball, wherever on the tangent plane the proxy
  // sits (an edge with another plane can hold it off the tangent point, and a lever there would spin a ball pushed
  // straight), and a push near a rod's end turns it.
  Eigen::Vector3d angular_impulse_Nms(const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& impulse_Ns) const {
    if (!shape_traits().normal_through_core) return (proxy_m - com_m).cross(impulse_Ns);
    const Eigen::Vector3d normal_part = impulse_Ns.dot(normal) * normal;
    const Eigen::Vector3d centre_m = point_m - shape.radius_m * normal;
    return (centre_m - com_m).cross(normal_part) + (proxy_m - com_m).cross(impulse_Ns - normal_part);
  }
};

// The planes one servo tick can hold: a frame's, and the triangles the mesh walk holds beyond one per mesh
// (mesh_walk.h: three at most in all, the first of each mesh in that mesh's own place).
inline constexpr std::uint32_t kMaxServoPlanes = kMaxPlanes + 2;

// Fixed-capacity set, filled in place each tick.
struct PlaneSet {
  std::array<ContactPlane, kMaxServoPlanes> planes{};
  std::uint32_t count = 0;
  // How far from the finger the planes describe the world (the frame's reach radius): the world sent every object
  // within it, so a proxy the planes place farther away may lie inside an object nobody sent (proxy_projection.h).
  double valid_within_m = std::numeric_limits<double>::infinity();
};

// Conversion of one world plane, unchanged.
ContactPlane to_contact_plane(const Plane& plane);

}  // namespace impetus
