// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spheres at the haptic rate. A plane is §3.1's first-order picture of a surface at the point nearest the proxy when
// the world stepped. For a face that picture holds across the face; for a sphere it holds only near its point, and
// between world frames (50–100 ms) the finger travels 10–25 mm, a radius or two of a small ball. Rendered as it
// came, a ball's tangent plane stretches without end: a finger passing beside the ball meets the plane where the
// ball is not, a pile of balls closes a pocket of tangent planes whose corners lie beside the balls, and the lever of
// a push far out on the plane spins a light ball (hard case 10: 3 g balls at 10 Hz).
//
// A sphere's plane carries its centre and radius (kPlaneSphere: centre = point − radius·normal, both moved with the
// interpolation or the local model), so the servo takes the tangent plane again every tick at the point of the sphere
// nearest to the last proxy, as Zilles & Salisbury's god-object follows a curved surface: the proxy walks over the
// ball instead of along a plane, and a push along the normal passes through the centre. Allocation-free.

#include "haptic_controller/contact_plane.h"

#include <Eigen/Core>

namespace impetus {

// Replaces each sphere plane of `planes` by the tangent plane at the sphere's point nearest `around_m` (the last
// proxy). A point at the centre keeps the plane as it is.
void retake_sphere_planes(PlaneSet& planes, const Eigen::Vector3d& around_m);

}  // namespace impetus
