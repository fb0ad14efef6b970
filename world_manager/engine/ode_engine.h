// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ODE implementation of RigidBodyEngine: a hash space, contact joints with the two materials combined
// (scene.h combine_*), QuickStep or the direct solver as the scene asks.
//
// The engine-neutral services run over it: escape handling (escape_guard.h), sleeping (sleeping_bodies.h: ODE's
// auto-disable is the rest rule; a sleeping body leaves ODE, whose solver walks every body it holds in every substep,
// disabled or not) and speculative contacts (speculative_contacts.h: rows with ODE's motionN). This file makes ODE's
// bodies, geoms and contact joints and answers what the services ask.
//
// The process must have called init_ode_once() (ode_runtime.h) first. Each engine keeps its own stream of ODE's
// global random generator (saved and restored around its steps), so runs are bitwise reproducible per engine even
// when several live in one process. Used from one thread.

#include "world_manager/engine/rigid_body_engine.h"
#include "world_manager/scene.h"

#include <memory>

namespace impetus {

class JsonNode;

// Reads ODE's block of a scene's physics (PhysicsParams::ode; engine_registry.h); throws SceneError.
void parse_ode_block(const JsonNode& block, PhysicsParams& physics);

class OdeEngine final : public RigidBodyEngine {
 public:
  // Builds the scene's bodies and geoms and seeds the generator with scene.physics.seed. Keeps a reference to
  // `scene`, which must outlive the engine.
  explicit OdeEngine(const Scene& scene);
  ~OdeEngine() override;
  OdeEngine(const OdeEngine&) = delete;
  OdeEngine& operator=(const OdeEngine&) = delete;

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
  const std::vector<std::size_t>& escaped() const override;
  std::vector<Overlap> overlaps(double min_depth_m) const override;
  void dent_top(std::size_t id, const DentedTop& top) override;

 private:
  struct Handles;
  std::unique_ptr<Handles> ode_;
};

}  // namespace impetus
