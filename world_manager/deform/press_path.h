// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a world period's push was given (docs/deformation.md): from the moments of the push into a surface over the
// period (impulse_ledger.h PressMoments), the straight stroke that has them. Exact for a contact that moved in a
// straight line at constant speed while pushing steadily (a press, a tap, a stroke); otherwise the stroke with the
// same centre, the same spread in time, and the same drift.
//
//     P = Σp,  x̄ = Σp·x / P,  t̄ = Σp·t / P,  σ² = Σp·t² / P − t̄²,  v = (Σp·x·t / P − x̄·t̄) / σ²
//
// A steady push over a time window has its times spread uniformly, over ±√3·σ about t̄: the stroke runs from
// x̄ − v·√3·σ to x̄ + v·√3·σ, and the push is shared evenly along it.

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
