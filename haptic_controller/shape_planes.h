// SPDX-License-Identifier: Apache-2.0
#pragma once
// Planes taken again at the proxy every tick, from the shape that travels with them. A plane is paper §3.1's
// first-order picture of a surface at the point nearest the proxy when the world stepped; between world frames
// (50–100 ms) the finger travels 10–25 mm, and the picture goes stale where the surface is not flat there: a ball's
// tangent plane stretches without end (a finger passing beside the ball meets the plane where the ball is not, and the
// lever of a push far out on it spins a light ball), and a box face's plane outlives the face (a finger that slides
// off an edge keeps feeling the face's press until the next frame). So every plane carries its body's shape, centre and
// axes (moved with the interpolation or the local model), and each tick the shape module takes the plane again under
// the proxy by its kind's rules (common/shape/shape.h retake_plane; each kind's file says how), as Zilles & Salisbury's
// god-object follows a curved surface: the proxy walks over a ball, rounds a cap, and leaves a face at its rim. A mesh
// whose triangles this process has is not retaken but walked (mesh_walk.h): its planes are the triangles the proxy's
// way meets, up to three.
//
// Allocation-free.

#include "haptic_controller/contact_plane.h"
#include "haptic_controller/mesh_walk.h"

#include <Eigen/Core>

namespace impetus {

// Replaces each plane that carries a shape by that shape's plane taken again about `around_m` (the last proxy). A
// point at a round body's centre keeps the plane as it is.
void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& around_m);

// The servo's form: as above about the last proxy, except for a body the straight way from the proxy to the finger
// does not enter. The god-object then goes straight to the finger past that body, which holds it back nowhere, so
// the body's plane is taken about the finger instead: its supporting plane at the point nearest the finger, with the
// body behind it and the finger in front. Taken about the proxy, the plane past an edge or a rim is the edge's
// tangent plane there; a finger that has left the body over the edge can still be behind it, and the proxy slides
// along it, off the body, holding the finger for a few more ticks. `mesh_hold`, kept by the caller from tick to
// tick, lets the meshes' walk start from the triangles it held last (mesh_walk.h).
void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m,
                         MeshHold* mesh_hold = nullptr);

}  // namespace impetus
