// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/escape_guard.h"

#include "world_manager/scene.h"

#include <cmath>

namespace impetus {

void EscapeGuard::check(std::span<const std::size_t> candidates, Engine& engine) {
  for (const std::size_t id : candidates) check_one(id, engine);
}

void EscapeGuard::check_all(Engine& engine) {
  for (std::size_t id = 0; id < is_escaped_.size(); ++id) check_one(id, engine);
}

void EscapeGuard::check_one(std::size_t id, Engine& engine) {
  if (is_escaped_[id]) return;
  const std::optional<BodyState> state = engine.escape_state(id);
  if (!state) return;
  const Eigen::Vector3d& v = state->velocity_mps;
  const Eigen::Vector3d& w = state->angular_velocity_radps;
  // A sum is finite only if every term is: one test per vector.
  const bool finite =
      state->position_m.allFinite() && std::isfinite(v[0] + v[1] + v[2]) && std::isfinite(w[0] + w[1] + w[2]);
  if (finite && state->position_m.lpNorm<Eigen::Infinity>() <= kEscapeDistance_m) return;
  Eigen::Vector3d parked_m = state->position_m;
  if (!parked_m.allFinite()) parked_m = Eigen::Vector3d(kEscapeDistance_m, 0.0, 0.0);
  const Eigen::Vector4d& q = state->orientation_wxyz;
  engine.park(id, parked_m, !std::isfinite(q[0] + q[1] + q[2] + q[3]));
  is_escaped_[id] = true;
  escaped_.push_back(id);
}

}  // namespace impetus
