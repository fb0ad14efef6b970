// SPDX-License-Identifier: Apache-2.0
#pragma once
// Speculative contacts: the contacts a pair that does not touch yet would make within the next substep.
//
// A rigid body steps by v·h. A body that reaches another in the middle of a substep ends it inside, up to v·h deep
// (3.8 mm for a 0.76 m/s cube at 5 ms), and ODE then pushes the two apart at ERP·depth/h: a separating speed of
// about ERP·v/2 at any substep length, which no restitution asked for and which the contact never takes back.
// A speculative contact is made one substep early, where the pair is still apart by `gap`, and lets the two close
// at most that gap in the substep: the solver's row is relative normal speed ≥ −gap/h. If the pair would not reach
// it stays inactive (no force); if it would, the pair meets exactly at the surface with the momentum exchange of a
// contact, and nothing is left to correct.
//
// Found by moving the body by its free displacement for the substep (its velocity after gravity and the applied
// forces, times h) and colliding it there: each contact point of that overlap, carried back by the displacement,
// is a point where the pair closes along the contact normal. Translation only: the turn within one substep is left
// to ordinary contacts, as before.

#include <Eigen/Core>
#include <ode/ode.h>

namespace impetus {

// The contacts of `moving` (attached to `body`) against `other` if the body moved by `displacement_m` (world frame,
// relative to `other`'s own displacement) in the coming substep. Writes at most `capacity` contacts to `out`, each
// with ODE's geometry fields: `pos` where the pair is at the substep's start (midway across the gap), `normal` pushing
// `moving` out of `other`, and `depth` = −gap, the signed separation along the normal at the start (< 0 where the
// pair is still apart, ≥ 0 where it already overlaps). Returns the count (0: the pair does not meet in the substep).
// The body is moved for the test and put back exactly where it was.
int speculative_contacts(dGeomID moving, dBodyID body, dGeomID other, const Eigen::Vector3d& displacement_m,
                         dContact* out, int capacity);

}  // namespace impetus
