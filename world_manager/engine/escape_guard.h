// SPDX-License-Identifier: Apache-2.0
#pragma once
// Bodies a solver throws out of range, taken out of the simulation: an engine-neutral world service
// (docs/architecture.md §7). A solver can throw a body to 10^300 m or make its state NaN (a stiff contact, a huge
// impulse); broadphases store coordinates in cells and abort on such values (ODE's hash space does), and every later
// step would carry the NaN. So an engine asks the guard before each broadphase and before the world reads its state:
// a body beyond kEscapeDistance_m (scene.h), or whose state is not finite, is stopped where it is (on the ray it left
// along, or at the escape distance on +x when its position is not finite), its orientation made the identity if that
// is not finite, and taken out of gravity and collisions for good. The world reports it (summary escaped_objects).
//
// The guard decides; the engine does (EscapeGuard::Engine). Used from the world's thread.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace impetus {

class EscapeGuard {
 public:
  // What the guard reads of a simulated body, world frame.
  struct BodyState {
    Eigen::Vector3d position_m;
    Eigen::Vector3d velocity_mps;
    Eigen::Vector3d angular_velocity_radps;
    Eigen::Vector4d orientation_wxyz;
  };
  // What the guard asks of an engine.
  class Engine {
   public:
    virtual ~Engine() = default;
    // Body `id`'s state, or nothing if the engine does not simulate it now (static, or asleep outside the solver).
    virtual std::optional<BodyState> escape_state(std::size_t id) const = 0;
    // Stops body `id` at `position_m` with zero velocities (and the identity orientation if `reset_orientation`),
    // and takes it out of gravity, the solver and collisions.
    virtual void park(std::size_t id, const Eigen::Vector3d& position_m, bool reset_orientation) = 0;
  };

  explicit EscapeGuard(std::size_t object_count) : is_escaped_(object_count, false) {}

  // Parks every body of `candidates` that has escaped since the last check.
  void check(std::span<const std::size_t> candidates, Engine& engine);
  // Every object id, 0 to object_count − 1.
  void check_all(Engine& engine);

  bool escaped(std::size_t id) const { return is_escaped_[id]; }
  // The escaped bodies, in order of escape.
  const std::vector<std::size_t>& escaped() const { return escaped_; }

 private:
  void check_one(std::size_t id, Engine& engine);

  std::vector<bool> is_escaped_;
  std::vector<std::size_t> escaped_;
};

}  // namespace impetus
