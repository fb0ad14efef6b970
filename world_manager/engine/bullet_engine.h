// SPDX-License-Identifier: Apache-2.0
#pragma once
// The Bullet implementation of RigidBodyEngine ("physics": {"engine": "bullet"}): Bullet 3.24's discrete dynamics
// world and sequential-impulse solver, in Debian's double-precision build (bullet-float64), so a body's state has the
// precision ODE's has and the two engines differ in their models, not in their rounding.
//
// What is the same on both engines, so a comparison measures the engines: the bodies' masses and inertias (the shape
// module's exact ones, not Bullet's box approximations), the scene's contact spring and damper on every contact
// (Bullet's per-contact stiffness and damping, which it maps to ERP and CFM by the same formulas ODE's numbers come
// from), the materials combined by the scene's rules (scene.h combine_*), the rest thresholds (sleeping_bodies.h),
// the escape guard (escape_guard.h). What is Bullet's own: its solver (sequential impulses with warm starting, or
// where the scene asks for a direct one its MLCP solver with Dantzig pivoting, as ODE's direct solver pivots), its
// friction (a pyramid of two fixed directions per contact point, as ODE's Approx1, but solved by sequential
// impulses), its contact points (kept in persistent manifolds; a point not yet touching lets the pair close the gap
// and no more, Bullet's own speculative contact), its island sleeping (a resting group of touching bodies sleeps
// together; islands are joined by contact points, as ODE's by contact joints), its continuous collision for fast
// bodies (where the scene asks for speculative contacts).
//
// Each engine is its own Bullet world; Bullet keeps no random state, so runs are bitwise reproducible. The combining
// rules and the rest time are Bullet's process-wide settings, set to the same values by every engine. Used from one
// thread.

#include "world_manager/engine/rigid_body_engine.h"
#include "world_manager/scene.h"

#include <memory>

namespace impetus {

class JsonNode;

// Reads Bullet's block of a scene's physics (PhysicsParams::bullet; engine_registry.h); throws SceneError.
void parse_bullet_block(const JsonNode& block, PhysicsParams& physics);

class BulletEngine final : public RigidBodyEngine {
 public:
  // Builds the scene's bodies. Keeps a reference to `scene`, which must outlive the engine.
  explicit BulletEngine(const Scene& scene);
  ~BulletEngine() override;

  void read_state(std::size_t id, ObjectState& out) const override;
  const Eigen::Matrix3d& inverse_inertia_body(std::size_t id) const override;
  void velocity(std::size_t id, Eigen::Vector3d& velocity_mps, Eigen::Vector3d& angular_radps) const override;
  void set_velocity(std::size_t id, const Eigen::Vector3d& velocity_mps, const Eigen::Vector3d& angular_radps) override;
  void wake(std::size_t id) override;
  bool asleep(std::size_t id) const override;
  void add_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) override;
  void add_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m) override;
  void step(int substeps, double substep_s, bool record_contacts, SubstepHook& hook) override;
  const std::vector<std::size_t>& moved() const override;
  ContactGraph& contacts() override;
  std::vector<Overlap> overlaps(double min_depth_m) const override;
  void dent_top(std::size_t id, const DentedTop& top) override;
  const std::vector<std::size_t>& escaped() const override;

 private:
  struct World;
  std::unique_ptr<World> bullet_;
};

}  // namespace impetus
