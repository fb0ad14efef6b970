// SPDX-License-Identifier: Apache-2.0
#pragma once
// How the haptic side's push reaches the world (docs/architecture.md §1.1 step 2): one strategy per coupling, chosen by
// --coupling. The World hands each strategy the new impulse the ledger found per dynamic object, lets it add forces
// before every engine substep, and lets it annotate the frame it publishes.
//
//   impulse   (paper §2.2, §3.5)  the impulse as a velocity change at the step's start, but for the part the
//                                  object's contacts can hold by friction, held as a force over the step
//   position  (the paper's previous method, §2.3)  a penalty force from the sampled finger, held over the step
//   local     (paper §6.3)  each impulse placed at the time it was rendered; frames carry contacts for the model

#include "common/contract/frames.h"
#include "world_manager/couplings/passivity_layer.h"
#include "world_manager/engine/rigid_body_engine.h"
#include "world_manager/features/feature_extractor.h"
#include "world_manager/impulse_ledger.h"
#include "world_manager/scene.h"

#include <Eigen/Core>

#include <memory>
#include <span>
#include <vector>

namespace impetus {

// Impulse the world applied, per object: in the last step and since the start (N·s, N·m·s about the CoM).
class AppliedImpulses {
 public:
  explicit AppliedImpulses(std::size_t object_count)
      : step_Ns_(object_count, Eigen::Vector3d::Zero()),
        total_Ns_(object_count, Eigen::Vector3d::Zero()),
        total_angular_Nms_(object_count, Eigen::Vector3d::Zero()) {}
  // O(objects given impulse in the last step), not O(objects).
  void begin_step() {
    for (const std::size_t id : stepped_) step_Ns_[id].setZero();
    stepped_.clear();
  }
  void add(std::size_t id, const Eigen::Vector3d& impulse_Ns, const Eigen::Vector3d& angular_impulse_Nms) {
    stepped_.push_back(id);
    step_Ns_[id] += impulse_Ns;
    total_Ns_[id] += impulse_Ns;
    total_angular_Nms_[id] += angular_impulse_Nms;
  }
  const Eigen::Vector3d& step_Ns(std::size_t id) const { return step_Ns_[id]; }
  const Eigen::Vector3d& total_Ns(std::size_t id) const { return total_Ns_[id]; }
  const Eigen::Vector3d& total_angular_Nms(std::size_t id) const { return total_angular_Nms_[id]; }

 private:
  std::vector<Eigen::Vector3d> step_Ns_;
  std::vector<std::size_t> stepped_;  // ids add() named since begin_step (repeats allowed)
  std::vector<Eigen::Vector3d> total_Ns_;
  std::vector<Eigen::Vector3d> total_angular_Nms_;
};

// When the impulses of one report were rendered, in haptic session time: the window since the previous report the
// world applied, mapped onto this world step.
struct RenderWindow {
  double start_s = 0.0;
  double length_s = 0.0;
  double tick_s = 0.0;  // the haptic tick's length, each tick's impulse a force over the tick before its time (0: unknown)
};

// What a coupling works on; owned by the World, valid for the World's lifetime.
struct CouplingContext {
  const Scene& scene;
  double world_period_s;
  int substeps;
  RigidBodyEngine& engine;
  std::span<ObjectState> states;  // after the last step; velocities updated by velocity changes
  AppliedImpulses& applied;
  // Every push goes through it (push_force, push_force_at, change_velocity), so the port's energy is booked.
  PassivityLayer& port;
};

// Where the finger is, for position coupling (the sampled finger of the newest report).
struct FingerState {
  ReachQuery finger;
  bool valid = false;
};

class CouplingStrategy : public SubstepHook {
 public:
  explicit CouplingStrategy(const CouplingContext& context) : context_(context) {}

  virtual Coupling kind() const = 0;
  // The ledger's new impulse on dynamic object `id` from one report, with its first moments in time (`moment`,
  // meaningful when `moment_finite`) and the window it was rendered in.
  virtual void take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment,
                            bool moment_finite, const RenderWindow& window) = 0;
  // After the reports, before the engine steps: the sampled finger of every endpoint slot (index = slot; an
  // endpoint without a usable finger has valid == false).
  virtual void before_step(std::span<const FingerState>, const FeatureExtractor&) {}
  void before_substep(int) override {}
  // Books the work of the substep's pushes and, with the layer on, takes out what the hands did not put in.
  void after_substep(int) final;
  // After the engine's last substep.
  virtual void after_step() {}
  // Whether the engine must record the last substep's contacts for annotate().
  virtual bool needs_contacts() const { return false; }
  // Adds what the coupling sends the haptic side to a frame about to be published.
  virtual void annotate(PlaneFrame&) {}

 protected:
  // Paper §3.5: v_i = v_{i−1} + F_i/m and I·ω_i = I·ω_{i−1} + L_i, applied as an instantaneous velocity change (not
  // a force over a substep), with the inertia at the current orientation: Δω = I_world⁻¹·L. Wakes the body.
  void apply_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                             const Eigen::Vector3d& angular_impulse_Nms);
  // The velocity change alone; the caller records the impulse in context_.applied.
  void change_velocity(std::size_t id, const Eigen::Vector3d& impulse_Ns, const Eigen::Vector3d& angular_impulse_Nms);
  double substep_s() const { return context_.world_period_s / context_.substeps; }
  // Velocity changes and forces go through the port (passivity_layer.h), which may admit only part of them (the part
  // withheld is counted there; context_.applied keeps what the coupling took from the reports).
  // A force (and torque about the centre of mass) held over the coming substep.
  void push_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm);
  // A force at a world point, held over the coming substep.
  void push_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m);

  CouplingContext context_;
};

std::unique_ptr<CouplingStrategy> make_coupling(Coupling coupling, const CouplingContext& context,
                                                double position_stiffness_Npm, double position_damping_Nspm);

}  // namespace impetus
