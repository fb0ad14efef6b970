// SPDX-License-Identifier: Apache-2.0
#pragma once
// Position coupling, the paper's previous method (§2.3, fig. 3 "d"): the world samples the finger once per step, and
// the finger's penetration d into each dynamic object gives a penalty force k_p·d + k_d·ḋ along the inward normal,
// held for the whole world period. Each endpoint's finger pushes on its own; their forces add. The report's impulses still advance the ledger (so its counters stay in step) but
// move nothing. The finger keeps the face it met while an object moves onto it (feature_memory.h), so an object that
// arrives faster than half its size per period is pushed back by its near face, not pulled through by its far one.

#include "world_manager/couplings/coupling.h"

#include <array>
#include <span>
#include <vector>

namespace impetus {

class PositionCoupling final : public CouplingStrategy {
 public:
  // k_p and k_d of the penalty (N/m, N·s/m); the World passes the scene's haptic stiffness and damping, so both
  // couplings see the same surface.
  PositionCoupling(const CouplingContext& context, double stiffness_Npm, double damping_Nspm);

  Coupling kind() const override { return Coupling::position; }
  void take_impulse(std::size_t, const ImpulseDelta&, const ImpulseDelta&, bool, const RenderWindow&) override {}
  void before_step(std::span<const FingerState> fingers, const FeatureExtractor& features) override;
  void before_substep(int substep) override;

 private:
  double stiffness_Npm_;
  double damping_Nspm_;
  // One finger's penalty on one object, held during the step at the surface point it acts on.
  struct Push {
    std::size_t object_id;
    Eigen::Vector3d force_N;
    Eigen::Vector3d point_m;
  };
  std::vector<Push> pushes_;              // this step's, every finger; reused between steps
  std::vector<ReachCandidate> touching_;  // reused between steps
  // Per endpoint slot: the face of each object that finger met, step to step.
  std::array<FeatureMemory, kMaxEndpoints> finger_faces_;
};

}  // namespace impetus
