// SPDX-License-Identifier: Apache-2.0
#pragma once
// Planes taken again at the proxy every tick, from the shape that travels with them. A plane is §3.1's first-order
// picture of a surface at the point nearest the proxy when the world stepped; between world frames (50–100 ms) the
// finger travels 10–25 mm, and the picture goes stale where the surface is not flat there.
//
// Spheres. For a face that picture holds across the face; for a sphere only near its point. Rendered as it came, a
// ball's tangent plane stretches without end: a finger passing beside the ball meets the plane where the ball is not,
// a pile of balls closes a pocket of tangent planes whose corners lie beside the balls, and the lever of a push far
// out on the plane spins a light ball (hard case 10: 3 g balls at 10 Hz). A sphere's plane carries its centre and
// radius (kPlaneSphere: centre = point − radius·normal, both moved with the interpolation or the local model), so the
// tangent plane is taken again at the point of the sphere nearest to the last proxy, as Zilles & Salisbury's
// god-object follows a curved surface: the proxy walks over the ball instead of along a plane, and a push along the
// normal passes through the centre.
//
// Boxes. A face's plane outlives the face: a finger that slides off an edge kept feeling the face's full press until
// the next world frame (up to a period), as if the face went on. A box's plane carries the box (kPlaneBox: its axes
// and half sizes, its centre the plane's com_m, all moved with the interpolation or the local model). The plane
// belongs to the face whose normal is nearest its own. While the last proxy lies over that face (outside the box with
// the face's point nearest), on it, or deep inside the box (the world chose the face), the plane stays as it came, so
// everything the interpolation and the local model do on a face is unchanged. Once the proxy has passed the face's rim
// the plane is the box's at its point nearest the proxy: an edge or corner (normal from that point to the proxy), or
// the neighbouring face the proxy went round to, or lies on. So the force ends within a tick of the finger leaving the
// face, and a finger that wraps round an edge meets the side face at once.
//
// Allocation-free.

#include "haptic_controller/contact_plane.h"

#include <Eigen/Core>

namespace impetus {

// Capsules. A capsule is the set of points within its radius of its axis segment: its plane is a sphere's about the
// axis point nearest the proxy (kPlaneCapsule: the axes, half length and radius travel with it), so the finger
// follows the side and rounds the caps every tick, and leaves the capsule where the capsule ends.
//
// Cylinders. Flat caps and a curved side (kPlaneCylinder: axes, half length and radius travel with it): a cap's plane
// ends at its rim as a box face's does, a side's plane is taken again under the proxy every tick, and past either
// the plane is the cylinder's nearest rim or part. On the surface the plane is the part's the proxy is on; inside,
// the part's the plane faces, on the true surface (a plane blended between two frames may cut into the body).
//
// Replaces each sphere plane of `planes` by the tangent plane at the sphere's point nearest `around_m` (the last
// proxy), each capsule plane likewise about the axis point nearest it, each box plane by the rules for boxes above,
// and each cylinder plane by the rules for cylinders. A point at a sphere's or a capsule's centre keeps the plane as
// it is.
void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& around_m);

// The servo's form: as above about the last proxy, except for a body the straight way from the proxy to the finger
// does not enter. The god-object then goes straight to the finger past that body, which holds it back nowhere, so
// the body's plane is taken about the finger instead: its supporting plane at the point nearest the finger, with the
// body behind it and the finger in front. Taken about the proxy, the plane past an edge or a rim is the edge's
// tangent plane there; a finger that has left the body over the edge can still be behind it, and the proxy slides
// along it, off the body, holding the finger for a few more ticks.
void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m);

}  // namespace impetus
