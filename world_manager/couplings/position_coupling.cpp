// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/position_coupling.h"

#include <algorithm>

namespace impetus {

PositionCoupling::PositionCoupling(const CouplingContext& context, double stiffness_Npm, double damping_Nspm)
    : CouplingStrategy(context), stiffness_Npm_(stiffness_Npm), damping_Nspm_(damping_Nspm) {}

void PositionCoupling::before_step(std::span<const FingerState> fingers, const FeatureExtractor& features) {
  pushes_.clear();
  const double period_s = context_.world_period_s;
  for (std::size_t slot = 0; slot < fingers.size() && slot < finger_faces_.size(); ++slot) {
    const FingerState& finger = fingers[slot];
    FeatureMemory& faces = finger_faces_[slot];
    if (!finger.valid) continue;  // the faces are remembered across steps without a finger (World::publish)
    faces.begin_step(context_.scene.objects.size());
    // Only the objects near the finger can be penetrated, so the feature index narrows the search.
    touching_.clear();
    features.within_reach(finger.finger, context_.states, 0.0, touching_, &faces);
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
      const Eigen::Vector3d force_N = -push_N * normal;
      pushes_.push_back({id, force_N, candidate.surface.point_m});
      context_.applied.add(id, force_N * period_s, lever_m.cross(force_N) * period_s);
    }
  }
}

void PositionCoupling::before_substep(int) {
  // The engine clears forces after every substep, so the held penalty forces are added again each substep.
  for (const Push& push : pushes_) {
    if (push.force_N.isZero(0.0)) continue;
    context_.engine.wake(push.object_id);
    push_force_at(push.object_id, push.force_N, push.point_m);
  }
}

}  // namespace impetus
