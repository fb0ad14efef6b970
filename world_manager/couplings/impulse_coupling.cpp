// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/impulse_coupling.h"

#include <algorithm>

namespace impetus {

ImpulseCoupling::ImpulseCoupling(const CouplingContext& context)
    : CouplingStrategy(context),
      force_N_(context.scene.objects.size(), Eigen::Vector3d::Zero()),
      torque_Nm_(context.scene.objects.size(), Eigen::Vector3d::Zero()) {
  held_.reserve(context.scene.objects.size());
}

void ImpulseCoupling::take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta&, bool,
                                   const RenderWindow&) {
  const double period_s = context_.world_period_s;
  const double magnitude_Ns = delta.impulse_Ns.norm();
  // What the body's contacts hold of a steady push (header, H): their friction, and the part of its weight the
  // supports do not carry where the push stands against it (a cube held on a slope).
  const auto body = static_cast<std::int32_t>(id);
  const ContactGraph& contacts = context_.engine.contacts();
  double holding_N = contacts.friction_capacity_N(body);
  const double inverse_mass_per_kg = context_.states[id].inverse_mass_per_kg;
  if (contacts.touching(body) && inverse_mass_per_kg > 0.0 && magnitude_Ns > 0.0) {
    const Eigen::Vector3d loose_N =
        contacts.unsupported_weight_N(body, to_eigen(context_.scene.gravity_mps2) / inverse_mass_per_kg);
    holding_N += std::max(0.0, -loose_N.dot(delta.impulse_Ns) / magnitude_Ns);
  }
  const double holdable_Ns = holding_N * period_s;
  const double held_share = !(holdable_Ns > 0.0) ? 0.0 : magnitude_Ns > holdable_Ns ? holdable_Ns / magnitude_Ns : 1.0;
  if (held_share < 1.0) {
    change_velocity(id, (1.0 - held_share) * delta.impulse_Ns, (1.0 - held_share) * delta.angular_impulse_Nms);
  }
  if (held_share > 0.0) {
    if (force_N_[id].isZero(0.0) && torque_Nm_[id].isZero(0.0)) held_.push_back(id);
    force_N_[id] += held_share * delta.impulse_Ns / period_s;
    torque_Nm_[id] += held_share * delta.angular_impulse_Nms / period_s;
    context_.engine.wake(id);
  }
  context_.applied.add(id, delta.impulse_Ns, delta.angular_impulse_Nms);
}

void ImpulseCoupling::before_substep(int) {
  // The engine clears forces after every substep: hand them in again each time.
  for (const std::size_t id : held_) push_force(id, force_N_[id], torque_Nm_[id]);
}

void ImpulseCoupling::after_step() {
  for (const std::size_t id : held_) {
    force_N_[id].setZero();
    torque_Nm_[id].setZero();
  }
  held_.clear();
}

}  // namespace impetus
