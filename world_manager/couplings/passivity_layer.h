// SPDX-License-Identifier: Apache-2.0
#pragma once
// The impulse port's energy books, and the passivity layer that keeps them (docs/architecture.md §6; measured in
// docs/latency.md, "The passivity layer").
//
// Every push a coupling gives a body goes through here, so the world knows, per dynamic object, the work its couplings
// did on it (the port's output, signed: a push against the body's motion takes energy out) beside the energy the hands
// put in to push it (the port's input, reported by the haptic side as ObjectImpulse::hand_input_J). Both are running
// totals since the start, summed over every endpoint that pushed the object: energy belongs to the body, whoever
// pushed it.
//
//   port work   a velocity change (J, L):   J·(v₀+v₁)/2 + L·(ω₀+ω₁)/2       (exact: the kinetic energy it adds)
//               a force (F, τ) held over a substep h:   h·(F·(v₀+v₁)/2 + τ·(ω₀+ω₁)/2)   (the kinetic energy it gives
//                                                        a free body, exactly; v₀ before the substep, v₁ after it)
//   hand input  Σ over haptic ticks of max(0, J_k·v_k): the body's share of the tick's reaction times the finger's
//               velocity over the tick before, where the hand pushed (haptic_controller/impulse_accumulator.h). Energy the hand takes back (a hand giving way) is not subtracted: the haptic
//               side's own spring and damper decide what reaches the hand, and an object that gave its energy to the
//               port (work < 0) may take it back whatever the hand did meanwhile.
//
// The layer (a switch, WorldOptions::passivity) is a time-domain passivity controller on the world's side of the port
// (after Hannaford & Ryu's observer and controller; the input it compares with is the newest the world has received,
// as in Ryu & Preusche's time-delay power network, so the rule holds at any link delay). It keeps output ≤ input in
// two stages:
//   1. It admits each push only as far as the budget B = input − output allows, scaling it by α ∈ [0, 1]:
//        a velocity change: its kinetic energy gain ΔKE(α) = α·(J·v₀ + L·ω₀) + α²·½(J·M⁻¹J + L·I⁻¹L) is exact, so
//        α is the largest with ΔKE(α) ≤ B (a push against the motion, ΔKE < 0, always goes in whole);
//        a force (F, τ) over a substep h: the work booked after it, h·(F·(v₀+v₁)/2 + τ·(ω₀+ω₁)/2), is on a free
//        body under gravity g exactly α·a + α²·b with a = h·(F·(v₀ + ½·h·g) + τ·ω₀) and b = ½·h²·(F·M⁻¹F + τ·I⁻¹τ);
//        the same α rule. A push that holds a body against gravity adds nothing (b cancels gravity's part of a);
//        what contacts take or give within the substep is booked after it and settled by stage 2.
//      So the layer withholds a push that would add energy to a free body, never a velocity change that brakes one.
//      A force pressing a body onto a support counts as free-body energy, so with no budget it is withheld as well,
//      although the support takes it (hard case 4 under position coupling, docs/latency.md).
//   2. After each substep, whatever output still exceeds the input is taken out of the body by scaling its velocity
//      and angular velocity by λ = √(1 − excess/KE), a damper that removes exactly the excess. Where the body has less
//      kinetic energy than that (the energy went into height, or into other bodies), what cannot be taken is counted
//      as unrecovered_J and the books start level again, rather than freezing the body until it is repaid.
//   3. After each world step, what an object's budget held unspent through the whole step, its lowest level since
//      the step before (the hand's input it did not take, and what it gave the port by being braked), is handed back
//      to the hands that pushed it that step (return_unspent), whose half of the layer
//      (haptic_controller/hand_port.h) lets the finger have it, or sends it on again behind the next push. What came
//      in or was freed during the step stays one step more: a body held against gravity takes energy and gives it
//      back within a step, and needs what it gave for the next push. Handed back, it leaves the object's budget:
//      energy is spent on one side of the port, never on both.
// What the layer withholds or takes out is counted: the energy the withheld part of each push would have given the body,
// as stage 1 predicts it (withheld_J: exact for a velocity change, at the velocity before the substep for a force), the
// kinetic energy stage 2 took out (damped_J), and the momentum, Σ of |ΔJ| withheld and m·|Δv| damped
// (removed_impulse_Ns). Off, the books are kept all the same and say what the couplings gained.

#include "world_manager/engine/rigid_body_engine.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace impetus {

// One dynamic object's port books, J and N·s, since the start.
struct PortEnergy {
  double hand_input_J = 0.0;        // energy the hands put in pushing it (reported)
  double port_work_J = 0.0;         // work the couplings' pushes did on it, net of what the layer took out
  double withheld_J = 0.0;          // energy the pushes would have given beyond the budget (stage 1's prediction)
  double damped_J = 0.0;            // kinetic energy taken out of the body (stage 2)
  double removed_impulse_Ns = 0.0;  // momentum it withheld or took out, Σ|ΔJ|
  double unrecovered_J = 0.0;       // output beyond input it could not take back (the body had no kinetic energy left)
  double returned_J = 0.0;          // handed back to the hands (stage 3)
  std::uint64_t interventions = 0;  // pushes it scaled down, and dampings
  // Output and what was handed back beyond input now (with the layer on, 0 after every settle()).
  double overdraft_J() const {
    const double out_J = port_work_J + returned_J;
    return out_J > hand_input_J ? out_J - hand_input_J : 0.0;
  }
};

class PassivityLayer {
 public:
  // `states` are the World's object states (their inverse masses); `engine` the bodies. Both outlive the layer.
  // `gravity_mps2` is the scene's: a force's admission counts the substep's fall under it (stage 1).
  PassivityLayer(std::span<const ObjectState> states, RigidBodyEngine& engine, bool enabled,
                 const Eigen::Vector3d& gravity_mps2 = Eigen::Vector3d::Zero());

  bool enabled() const { return enabled_; }

  // The hands' new input to dynamic object `id` from one report (the ledger's difference), J.
  void add_hand_input(std::size_t id, double work_J);
  // The share α ∈ [0, 1] of a velocity change (impulse_Ns, angular_impulse_Nms) on a body moving at (v0, w0) that the
  // budget admits (1 with the layer off), counting what it withholds; inverse mass and world inverse inertia as in
  // ObjectState. The caller applies α times the change and then books it with record_velocity_change.
  double admit_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                               const Eigen::Vector3d& angular_impulse_Nms, const Eigen::Vector3d& v0_mps,
                               const Eigen::Vector3d& w0_radps, double inverse_mass_per_kg,
                               const Eigen::Matrix3d& inverse_inertia_world);
  // A velocity change the coupling made: from (v0, w0) to (v1, w1) by (impulse_Ns, angular_impulse_Nms).
  void record_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                              const Eigen::Vector3d& angular_impulse_Nms, const Eigen::Vector3d& v0_mps,
                              const Eigen::Vector3d& w0_radps, const Eigen::Vector3d& v1_mps,
                              const Eigen::Vector3d& w1_radps);
  // The share α ∈ [0, 1] of a force and torque about the centre of mass, held over the coming substep of `substep_s`,
  // that the budget admits at the body's velocity now (1 with the layer off), counting what it withholds. The caller
  // adds α times them to the engine and books them with record_force.
  double admit_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm,
                     double substep_s);
  // A force and torque about the centre of mass the coupling holds over the coming substep.
  void record_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm);
  // After a substep of `substep_s`: books the work of the forces recorded for it, at the velocities the engine reached.
  void after_substep(double substep_s);
  // Enforces output ≤ input on every object booked since the last call (no-op when the layer is off).
  void settle();
  // Stage 3: takes what object `id`'s budget has held since the last call out of it, to hand back to the hands (0
  // when the layer is off or nothing was left unspent). Call after settle().
  double return_unspent(std::size_t id);

  const PortEnergy& energy(std::size_t id) const { return books_[id]; }
  // Sums over objects.
  PortEnergy total() const;

 private:
  // Input − output − handed back − work admitted but not booked yet, J.
  double budget_J(std::size_t id) const;
  // Counts an intervention: energy withheld from a push (stage 1) or damped out of the body (stage 2), and momentum.
  void count(std::size_t id, double withheld_J, double damped_J, double impulse_Ns);
  void touch(std::size_t id);
  void enforce(std::size_t id);

  std::span<const ObjectState> states_;
  RigidBodyEngine& engine_;
  bool enabled_;
  Eigen::Vector3d gravity_mps2_;
  std::vector<PortEnergy> books_;
  // Forces held over the current substep, per object, and which objects have one.
  std::vector<Eigen::Vector3d> force_N_;
  std::vector<Eigen::Vector3d> torque_Nm_;
  std::vector<std::size_t> forced_;
  std::vector<bool> is_forced_;
  // Work admitted for the current substep's forces, not booked yet (several pushes on one body share the budget), and
  // the velocities the body had before the substep.
  std::vector<double> admitted_J_;
  std::vector<double> low_water_J_;  // the lowest budget since the last return_unspent(), J
  std::vector<Eigen::Vector3d> velocity_before_mps_;
  std::vector<Eigen::Vector3d> angular_before_radps_;
  // Objects whose books changed since the last settle().
  std::vector<std::size_t> touched_;
  std::vector<bool> is_touched_;
};

}  // namespace impetus
