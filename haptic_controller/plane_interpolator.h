// SPDX-License-Identifier: Apache-2.0
#pragma once
// Plane interpolation between world frames i−1 and i (paper §3.2, docs/architecture.md §1.2 step 2).
//
//   P_H = w·P_Wi + (1 − w)·P_W(i−1),   N_H = w·N_Wi + (1 − w)·N_W(i−1)   (paper §3.2 with w = j/n)
//
// Rules beyond the paper:
//  * Planes are matched across frames by object_id (the k-th plane of an object in frame i with its k-th plane in
//    frame i−1). A plane whose object is absent from frame i−1 starts at frame i's value (no sweep from nowhere); an
//    object absent from frame i is gone.
//  * The interpolated normal is renormalised. If the two normals are more than 90° apart (dot < 0: the finger passed
//    over an edge or through a thin object and the nearest point jumped to another face), linear blending would pass
//    through a vanishing normal and sweep the plane through the object; instead the whole plane switches from frame
//    i−1's to frame i's at the midpoint, w ≥ ½. For dot ≥ 0 the blended normal has length ≥ 1/√2, never near zero.
//    A plane that carries its body's axes (ShapeTraits::carries_axes) shows the same face, but carried rigidly with
//    the body's interpolated pose (centre lerped, axes turned part of the way): a face held where frame i−1 left it would let a
//    body that comes at the finger close over the proxy for half a period.
//  * The centre of mass is interpolated like the point; velocities, friction and flags are frame i's (the newest
//    state the world has sent, §6.2).
//  * Where the normal turns, the plane turns about the pivot (the last proxy), not about its point: its signed
//    distance from the pivot moves linearly, d(w) = (1 − w)·d_{i−1} + w·d_i, and the point slides along the new normal
//    to match (keeping its place along the surface). Turning about a point 15 mm from the finger (a box's top face
//    whose next frame is the edge the finger slid past) drops the plane 0.3 mm at the finger in one tick, and the
//    damper turns that into a pull on the finger (hard case 6). For planes that do not turn this is the paper's rule.
//  * A ball's plane (ShapeTraits::round) interpolates the centre instead; the servo then takes the tangent plane at the
//    proxy (shape_planes.h).

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/plane_matching.h"

namespace impetus {

// w = (now − arrival of frame i) / T_w, clamped to [0, 1]; 1 if the period is not positive or anything is NaN.
double interpolation_weight(double now_s, double frame_arrival_s, double world_period_s);

// Fills `out` with frame i's planes interpolated at weight w from frame i−1, turning about `pivot_m` (the last proxy).
// `previous` may be the same object as `current` (first frame of a session). Allocation-free.
void interpolate_planes(const PlaneFrame& previous, const PlaneFrame& current, double w, const Eigen::Vector3d& pivot_m,
                        PlaneSet& out);
// The same with the frames' planes already matched (match_planes(previous, current), plane_matching.h): a servo that
// interpolates the same two frames every tick of a period pairs their planes once.
void interpolate_planes(const PlaneFrame& previous, const PlaneFrame& current, const PlaneMatches& matches, double w,
                        const Eigen::Vector3d& pivot_m, PlaneSet& out);

}  // namespace impetus
