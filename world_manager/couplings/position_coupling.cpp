// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/position_coupling.h"

#include <algorithm>

namespace impetus {

PositionCoupling::PositionCoupling(const CouplingContext& context, double stiffness_Npm, double damping_Nspm)
    : CouplingStrategy(context),
      stiffness_Npm_(stiffness_Npm),
      damping_Nspm_(damping_Nspm),
      force_N_(context.scene.objects.size(), Eigen::Vector3d::Zero()),
      point_m_(context.scene.objects.size(), Eigen::Vector3d::Zero()) {}

void PositionCoupling::before_step(const FingerState& finger, const FeatureExtractor& features) {
  for (auto& force : force_N_) force.setZero();
  finger_faces_.begin_step(context_.scene.objects.size());
  if (!finger.valid) return;
  // Only the objects near the finger can be penetrated, so the feature index narrows the search.
  touching_.clear();
  features.within_reach(finger.finger, context_.states, 0.0, touching_, &finger_faces_);
  const double period_s = context_.world_period_s;
  for (const ReachCandidate& candidate : touching_) {
    const auto id = static_cast<std::size_t>(candidate.object_id);
    if (id >= context_.scene.objects.size() || !context_.scene.objects[id].dynamic) continue;
    const double depth_m = -candidate.surface.signed_distance_m;
    if (depth_m <= 0.0) continue;
    const ObjectState& state = context_.states[id];
    const Eigen::Vector3d& normal = candidate.surface.normal;
    const Eigen::Vector3d lever_m = candidate.surface.point_m - state.pose.position_m;
    const Eigen::Vector3d surface_velocity_mps = state.velocity_mps + state.angular_velocity_radps.cross(lever_m);
    const double depth_rate_mps = -(finger.finger.velocity_mps - surface_velocity_mps).dot(normal);
    // A contact can only push: a finger pulling out fast must not drag the object along.
    const double push_N = std::max(0.0, stiffness_Npm_ * depth_m + damping_Nspm_ * depth_rate_mps);
    force_N_[id] = -push_N * normal;
    point_m_[id] = candidate.surface.point_m;
    context_.applied.add(id, force_N_[id] * period_s, lever_m.cross(force_N_[id]) * period_s);
  }
}

void PositionCoupling::before_substep(int) {
  // The engine clears forces after every substep, so the held penalty force is added again each substep.
  for (std::size_t id = 0; id < force_N_.size(); ++id) {
    const Eigen::Vector3d& force_N = force_N_[id];
    if (force_N.isZero(0.0)) continue;
    context_.engine.wake(id);
    context_.engine.add_force_at(id, force_N, point_m_[id]);
  }
}

}  // namespace impetus
