#pragma once
// Impulse coupling (paper §2.2, §3.5): the force the haptic side integrated over the world period is applied as one
// velocity change at the start of the step, so contact friction in the step sees it.

#include "world_manager/couplings/coupling.h"

namespace impetus {

class ImpulseCoupling final : public CouplingStrategy {
 public:
  using CouplingStrategy::CouplingStrategy;
  Coupling kind() const override { return Coupling::impulse; }
  void take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta&, bool,
                    const RenderWindow&) override {
    apply_velocity_change(id, delta.impulse_Ns, delta.angular_impulse_Nms);
  }
};

}  // namespace impetus
