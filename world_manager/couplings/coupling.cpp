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
  const Eigen::Vector3d v0_mps = state.velocity_mps;
  const Eigen::Vector3d w0_radps = state.angular_velocity_radps;
  const double admitted = context_.port.admit_velocity_change(id, impulse_Ns, angular_impulse_Nms, v0_mps, w0_radps,
                                                              state.inverse_mass_per_kg, state.inverse_inertia_world);
  const Eigen::Vector3d impulse = admitted * impulse_Ns;
  const Eigen::Vector3d angular = admitted * angular_impulse_Nms;
  state.velocity_mps += state.inverse_mass_per_kg * impulse;
  state.angular_velocity_radps += state.inverse_inertia_world * angular;
  context_.engine.set_velocity(id, state.velocity_mps, state.angular_velocity_radps);
  context_.engine.wake(id);
  context_.port.record_velocity_change(id, impulse, angular, v0_mps, w0_radps, state.velocity_mps,
                                       state.angular_velocity_radps);
}

void CouplingStrategy::push_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) {
  const double admitted = context_.port.admit_force(id, force_N, torque_Nm, substep_s());
  context_.engine.add_force(id, admitted * force_N, admitted * torque_Nm);
  context_.port.record_force(id, admitted * force_N, admitted * torque_Nm);
}

void CouplingStrategy::push_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m) {
  // The engine turns it into a force and a torque about the centre of mass where the body is now.
  ObjectState now;
  context_.engine.read_state(id, now);
  const Eigen::Vector3d torque_Nm = (point_m - now.pose.position_m).cross(force_N);
  const double admitted = context_.port.admit_force(id, force_N, torque_Nm, substep_s());
  context_.engine.add_force_at(id, admitted * force_N, point_m);
  context_.port.record_force(id, admitted * force_N, admitted * torque_Nm);
}

void CouplingStrategy::after_substep(int) { context_.port.after_substep(substep_s()); }

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
