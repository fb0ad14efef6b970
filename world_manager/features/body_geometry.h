// SPDX-License-Identifier: Apache-2.0
#pragma once
// Analytic geometry of the scene's shapes: the nearest surface point to a query point and the outward normal there
// (paper §3.1 steps 2–3), and world-frame bounding boxes for the feature query. Pure functions, no ODE.
//
// Shapes are centred on the body origin (the centre of mass) with their axis along body z (DESIGN.md §4).

#include "world_manager/scene.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>

namespace impetus {

// Pose of a body: world = orientation · body + position.
struct BodyPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // unit
};

struct SurfacePoint {
  Eigen::Vector3d point_m;  // on the surface
  Eigen::Vector3d normal;   // unit, outward
  // Distance from the query point to the surface: positive outside, negative inside (−penetration depth).
  double signed_distance_m = 0.0;
};

// Nearest surface point to `query_m` (body frame). Inside the shape this is the nearest face, not the far side, and the
// normal still points outward there, so a penetrating finger is pushed out the short way. Where the nearest point is
// not unique (the exact centre of a sphere, the axis of a capsule or cylinder) a fixed direction is chosen (+z for a
// sphere, +x for the radial direction of a capsule or cylinder) so the answer is deterministic.
SurfacePoint nearest_surface_point_body(const Shape& shape, const Eigen::Vector3d& query_m);

// The faces of a box (`half_m`: half sizes) whose planes a body-frame point inside or on the box is nearest to, within
// `tolerance_m` of the nearest: their outward unit normals, lowest axis first, + side for a point on the mid-plane.
// One face for a point in a face's interior, two on an edge, three at a corner. A point outside by at most
// `tolerance_m` counts as on the surface (rounding puts a point meant to be on an edge on either side of it). Returns
// the count; 0 for a point farther outside.
int nearest_box_faces(const Eigen::Vector3d& half_m, const Eigen::Vector3d& q, double tolerance_m,
                      std::array<Eigen::Vector3d, 3>& normals);

// The same for a body in the world: query, result point and normal in the world frame.
SurfacePoint nearest_surface_point(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m);

// The shape's supporting plane with outward unit normal `normal_body` (body frame), taken at the query: the plane
// {x : n·x = h(n)}, h(n) = max over the shape of n·x (its support function), in the world; the result's point is the
// query projected onto that plane (for a sphere, the support point r·n, so that point − r·normal stays the centre),
// its normal n in the world, its signed distance n·query − h(n). For a box and a face
// normal this is the face's plane, whichever face is nearest to the query. Used to keep the face a query point met
// while an object moves onto it (feature_memory.h).
SurfacePoint supporting_plane(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m,
                              const Eigen::Vector3d& normal_body);

// Whether the segment from `from_m` to `to_m` (body frame) passes through the shape's interior: the least signed
// distance along it is negative. The shapes are convex, so the signed distance along a segment is a convex function
// of the position on it and a golden-section search finds its least value.
bool segment_enters_body(const Shape& shape, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m);

// How far from its point a plane of the shape still describes it (link_types.h Plane::extent_m): the radius of a
// sphere, capsule or cylinder (a tangent plane one radius from its point is beside the body, no longer on it), the
// space diagonal of a box (no two points of the box are farther apart, so a face has ended by then).
double plane_extent_m(const Shape& shape);

// Tight world-frame axis-aligned bounding box of the shape at `pose`.
Eigen::AlignedBox3d world_bounds(const Shape& shape, const BodyPose& pose);

}  // namespace impetus
