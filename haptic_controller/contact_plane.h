#pragma once
// The planes the servo renders in one tick: paper §3.1's (point, normal) pairs after interpolation (§3.2), in Eigen
// form, plus the object data needed for friction (§6.2) and for sharing the reaction among objects (§3.4).
//
// A plane is a half-space constraint: the proxy must satisfy normal·(x − point_m) ≥ 0. Owned by the servo thread.

#include "common/link_types.h"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include <array>
#include <cstdint>
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

  // Velocity of the object's material point at `x` (rigid body: v + ω × (x − com)).
  Eigen::Vector3d surface_velocity_mps(const Eigen::Vector3d& x_m) const {
    return velocity_mps + angular_velocity_radps.cross(x_m - com_m);
  }
  bool dynamic() const { return (flags & kPlaneDynamic) != 0; }
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
