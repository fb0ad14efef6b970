// SPDX-License-Identifier: Apache-2.0
#pragma once
// Impulse coupling (paper §2.2, §3.5): the impulse J the haptic side integrated over the last world period reaches the
// object in this world step, as the velocity change v_i = v_{i−1} + J/m at the step's start, except for the part the
// object's contacts could hold.
//
// Why the split: J is what a force did over a whole period T. Applied as one velocity change, friction meets it with
// the budget of one substep h = T/n, μ·N·h, and a steady push above μ·N/n makes a resting object creep although
// static friction holds it in the 1 kHz truth. Held over the step as the force J/T, friction meets it with μ·N·T, the
// budget of the period it was rendered in. But held over the step the push also arrives later (its centroid T/2 after
// the step starts), and a struck object lags the finger further. So the part the contacts could hold,
//     J_held = J·min(1, H·T / |J|),  H = μN + max(0, −W_loose·Ĵ)
// (μN: the contacts' friction capacity in the last step; W_loose: the body's weight less what its supports carry,
// contact_graph.h, which a push up a slope holds as well), is held as the force J_held/T over every substep, and the
// rest, which moves the object whatever friction does, is the velocity change of §3.5. A push the contacts can hold
// then stays held; a tap (|J| ≫ H·T) is still almost all a velocity change. Without the slope's share a cube held on
// a ramp by a still finger got kicks up the ramp and slid back between them, down through the finger once the
// passivity layer let no kick give more energy than the cube brought (docs/hard_cases.md, case 12). A free object has
// no contacts: all of J is a velocity change, the paper's update.
//
// Momentum is exact either way: the object receives J (and the angular impulse, split in the same proportion) in the
// step.

#include "world_manager/couplings/coupling.h"

#include <vector>

namespace impetus {

class ImpulseCoupling final : public CouplingStrategy {
 public:
  explicit ImpulseCoupling(const CouplingContext& context);

  Coupling kind() const override { return Coupling::impulse; }
  void take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta&, bool,
                    const RenderWindow&) override;
  void before_substep(int substep) override;
  void after_step() override;
  bool needs_contacts() const override { return true; }

 private:
  // Per object, the force and torque held over every substep of this step.
  std::vector<Eigen::Vector3d> force_N_;
  std::vector<Eigen::Vector3d> torque_Nm_;
  std::vector<std::size_t> held_;  // objects with a held force this step
};

}  // namespace impetus
