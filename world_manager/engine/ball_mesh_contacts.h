// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a ball touches a mesh body, from the mesh's own tree (common/mesh/mesh_bvh.h), for any size of triangle. ODE's
// sphere–trimesh test lets a ball fall through triangles much smaller than the ball (a 15 mm ball through a terrain of
// 1.3 mm cells; docs/meshes.md); the nearest points of the mesh to the ball's centre do not.
//
// Every triangle within the radius gives its point nearest the centre. The nearest of them is a contact; another is a
// contact too only if it lies in front of the tangent plane of every nearer contact (a ball in a valley rests on both
// sides), since a point on or behind that plane belongs to the same patch (a flat grid continues the plane, a dome
// curves away behind it). Each contact pushes the ball along the line from the mesh's point to its centre (the
// feature's pseudo-normal if the centre is behind the surface), as deep as the ball reaches past the point.
//
// Engine-neutral: the engine gives the ball and the mesh body's pose, and turns these into its own contacts.
// World frame, SI units. Allocation-free.

#include "common/mesh/mesh_body.h"

#include <Eigen/Core>

#include <span>

namespace impetus {

struct BallContact {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the mesh
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, from the mesh toward the ball: the push on the ball
  double depth_m = 0.0;                               // how far the ball reaches past the point, ≥ 0
};

// The contacts of the ball at `centre_m` of `radius_m` with `body` at `com_m` turned by `rotation` (body → world), at
// most `out.size()` (the nearest). Returns how many.
int ball_mesh_contacts(const Eigen::Vector3d& centre_m, double radius_m, const MeshBody& body,
                       const Eigen::Vector3d& com_m, const Eigen::Matrix3d& rotation, std::span<BallContact> out);

}  // namespace impetus
