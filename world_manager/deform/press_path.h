// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a world period's push was given (docs/deformation.md): from the moments of the push into a surface over the
// period (impulse_ledger.h PressMoments), the straight stroke that has them. Exact for a contact that moved in a
// straight line at constant speed while pushing steadily (a press, a tap, a stroke); otherwise the stroke with the
// same centre and the same spread along its main direction.
//
//     P = Σp,  x̄ = Σp·x / P,  C = Σp·x·xᵀ / P − x̄·x̄ᵀ  (the push's covariance in space),  C u = λ u, λ the largest
//
// A push spread evenly along a segment of length L has variance L²/12 along it: the stroke runs from
// x̄ − √(3λ)·u to x̄ + √(3λ)·u, and the push is shared evenly along it.

#include "world_manager/impulse_ledger.h"

#include <Eigen/Core>

namespace impetus {

struct PressStroke {
  double push_Ns = 0.0;                                // 0: nothing pushed
  Eigen::Vector3d from_m = Eigen::Vector3d::Zero();    // world frame
  Eigen::Vector3d to_m = Eigen::Vector3d::Zero();      // equal to from_m for a press that did not move
};

// The stroke of `moments` (a world period's differences). Non-finite or non-positive moments give no push.
PressStroke stroke_of(const PressMoments& moments);

}  // namespace impetus
