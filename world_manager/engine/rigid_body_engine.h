// SPDX-License-Identifier: Apache-2.0
#pragma once
// The rigid-body engine behind the world (docs/architecture.md §1.3): the scene's bodies, advanced in substeps. The
// World and the couplings see only this interface; ODE is one implementation (ode_engine.h).
//
// Ids are scene object indices. Velocities and forces are in the world frame, SI units. Static objects have no body:
// calls naming them are not allowed (callers check SceneObject::dynamic).

#include "world_manager/features/contact_graph.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace impetus {

// Called by RigidBodyEngine::step before each substep (couplings add their forces there) and after it (the impulse
// port books the work those forces did, couplings/passivity_layer.h).
class SubstepHook {
 public:
  virtual ~SubstepHook() = default;
  virtual void before_substep(int substep) = 0;
  virtual void after_substep(int /*substep*/) {}
};

// A static box's top face (its body +z face) as a grid of heights: a deformable slab (world_manager/deform/
// deformable_surface.h). Sample (c, r), row-major at r·columns + c, is the surface's height above the box's centre
// along its z at (c + ½, r + ½) cells from the face's −x, −y corner. The engine reads the heights whenever it
// collides: their owner keeps them alive and in place.
struct DentedTop {
  std::size_t columns = 0;
  std::size_t rows = 0;
  double cell_x_m = 0.0;
  double cell_y_m = 0.0;
  const double* height_m = nullptr;
  double floor_m = 0.0;   // no height will be below it (the slab's unyielding floor)
  double lowest_m = 0.0;  // the lowest height now
};

class RigidBodyEngine {
 public:
  virtual ~RigidBodyEngine() = default;

  // Pose, velocity and angular velocity of dynamic object `id` now (the mass properties of `out` are left alone).
  virtual void read_state(std::size_t id, ObjectState& out) const = 0;
  // Inverse inertia about the centre of mass in the body frame, 1/(kg·m²).
  virtual const Eigen::Matrix3d& inverse_inertia_body(std::size_t id) const = 0;

  virtual void velocity(std::size_t id, Eigen::Vector3d& velocity_mps, Eigen::Vector3d& angular_radps) const = 0;
  virtual void set_velocity(std::size_t id, const Eigen::Vector3d& velocity_mps,
                            const Eigen::Vector3d& angular_radps) = 0;
  // A sleeping body must wake to move. Engines that let bodies sleep (scene physics.auto_disable) also wake a body
  // that is given a force or a velocity, or that an awake body touches.
  virtual void wake(std::size_t id) = 0;
  // Whether dynamic object `id` sleeps: at rest, its pose fixed and its velocity zero, costing nothing per step.
  virtual bool asleep(std::size_t id) const = 0;
  // Held during the next substep only.
  virtual void add_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) = 0;
  virtual void add_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m) = 0;

  // Advances `substeps` substeps of `substep_s` each, calling hook.before_substep(s) first in each and
  // hook.after_substep(s) once the bodies have moved (before the next substep's collisions). With
  // `record_contacts` the contacts of the last substep, each with the normal force the substep found for it, replace
  // contacts() once that substep is done. Reproducible: the same calls from the same state give the same bits,
  // whatever other engines in the process do.
  virtual void step(int substeps, double substep_s, bool record_contacts, SubstepHook& hook) = 0;

  // The dynamic objects the last step simulated (awake at any time in it), ascending: the only ones whose state can
  // have changed since the step before. Every dynamic object before the first step.
  virtual const std::vector<std::size_t>& moved() const = 0;

  // The contacts recorded by the last step that recorded them (a sleeping body keeps those it fell asleep with).
  virtual ContactGraph& contacts() = 0;
  // Two objects whose geometry overlaps (b: another object's id, or the object count for the floor) by depth_m.
  struct Overlap {
    std::size_t a = 0;
    std::size_t b = 0;
    double depth_m = 0.0;
  };
  // Every pair with a dynamic body that overlaps by more than `min_depth_m` now, in order of a, then b: what a scene
  // placed inside another, which the solver would push apart on the first step. Changes nothing.
  virtual std::vector<Overlap> overlaps(double min_depth_m) const = 0;

  // Bodies rest on and roll over static box `id`'s dented top from the next step on: the engine collides them with
  // `top`'s heights above its lowest point and with the box below it. Called again whenever the heights changed (the
  // engine keeps the first call's pointer); wakes the bodies that may rest on the box.
  virtual void dent_top(std::size_t id, const DentedTop& top) = 0;

  // Objects taken out of the simulation because the solver threw them beyond kEscapeDistance_m (scene.h) or made their
  // state non-finite (engine/escape_guard.h, which every engine asks); they stay where they were taken out, at rest,
  // and collide with nothing. In order of escape.
  virtual const std::vector<std::size_t>& escaped() const = 0;
};

}  // namespace impetus
