// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/coupling.h"

#include "world_manager/couplings/impulse_coupling.h"
#include "world_manager/couplings/local_coupling.h"
#include "world_manager/couplings/position_coupling.h"

#include <stdexcept>

namespace impetus {

void CouplingStrategy::apply_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                                             const Eigen::Vector3d& angular_impulse_Nms) {
  change_velocity(id, impulse_Ns, angular_impulse_Nms);
  context_.applied.add(id, impulse_Ns, angular_impulse_Nms);
}

void CouplingStrategy::change_velocity(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                                       const Eigen::Vector3d& angular_impulse_Nms) {
  ObjectState& state = context_.states[id];
  state.velocity_mps += state.inverse_mass_per_kg * impulse_Ns;
  state.angular_velocity_radps += state.inverse_inertia_world * angular_impulse_Nms;
  context_.engine.set_velocity(id, state.velocity_mps, state.angular_velocity_radps);
  context_.engine.wake(id);
}

std::unique_ptr<CouplingStrategy> make_coupling(Coupling coupling, const CouplingContext& context,
                                                double position_stiffness_Npm, double position_damping_Nspm) {
  switch (coupling) {
    case Coupling::impulse: return std::make_unique<ImpulseCoupling>(context);
    case Coupling::position:
      return std::make_unique<PositionCoupling>(context, position_stiffness_Npm, position_damping_Nspm);
    case Coupling::local: return std::make_unique<LocalCoupling>(context);
  }
  throw std::invalid_argument("unknown coupling");
}

}  // namespace impetus
