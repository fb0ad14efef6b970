// SPDX-License-Identifier: Apache-2.0
#pragma once
// The passivity layer's half at the hand (docs/architecture.md §6; measured in docs/latency.md, "The passivity
// layer"). The world's half (world_manager/couplings/passivity_layer.h) keeps what the couplings give each body
// within the energy the hand sent it; this half keeps what the contact force gives the finger within the energy the
// finger put in and the world handed back. Together the port gives out no more than it took in, at any rate, phase,
// delay or loss: energy is a token held on one side or in flight, never on both (after Ryu, Artigas and Preusche's
// time-delay power network, where each side spends only what the other side sent).
//
// Books, exact for a force held over each tick (the device's zero-order hold): at tick k the finger has moved by
// Δx_k since tick k−1, under the force commanded then, f'_{k−1}, so the finger received w_k = f'_{k−1}·Δx_k:
//   input     += max(0, −w_k)              the hand's work against the force (pressing in)
//   output    += max(0,  w_k)              the force's work on the finger (pushing it out)
//   returned  += what the world handed back (PlaneFrame::port_returned_J's increments)
//   credited  += what the tick's pushes on dynamic objects carried to the world (ObjectImpulse::hand_input_J)
//   reservoir  = input + returned − output − credited
// 1. The damper. The tick's force f_k will do about f_k·Δx_k on the finger over the coming tick (the last
//    displacement as the prediction). Where that is more than the reservoir holds, a damper along Δx takes out the
//    difference: f'_k = f_k − d/|Δx_k|²·Δx_k, so the prediction is f'_k·Δx_k = reservoir. A wrong prediction is
//    booked exactly at the next tick and leaves the reservoir in debt, which later input pays before any output;
//    damped_J counts Σ (f − f')·Δx as it came. The prediction sees only the force along the last displacement: a
//    force whose direction jitters across the finger's motion (friction chatter as a cube slides past it) does work
//    it does not see (the deepest debt over the hard cases, docs/latency.md, "The passivity layer").
//    The contact force f itself is what the objects receive (the reaction the accumulator shares): the damper stands
//    between the finger and the port, not between the port and the world.
// 2. The credit. The hand keeps what its spring could give back, the proxy spring's stored energy ½·k·|D − C|², and
//    the coming tick's predicted output; whenever the finger pushes a dynamic object it sends the rest of the
//    reservoir to the world behind that push (in place of the accumulator's Σ max(0, J·v)). A press first fills the
//    spring and then pays for the object's motion; a finger that trembles against a held object draws its give-back
//    from what it pressed in.
// The world hands back what a body left unspent through a whole step: what it gave the port (a push that braked it)
// and the hand's input it did not take (a press on an object the floor holds). The next push sends it on again if the
// spring does not need it.
//
// Off (no frame, or frames without the layer) it changes nothing and books nothing. Owned by the servo thread;
// allocation-free.

#include "common/contract/frames.h"

#include <Eigen/Core>

#include <cstdint>

namespace impetus {

struct HandPortBooks {
  double input_J = 0.0;     // the hand's work against the contact force
  double output_J = 0.0;    // the commanded force's work on the finger
  double credited_J = 0.0;  // sent to the world behind pushes on dynamic objects
  double returned_J = 0.0;  // handed back by the world
  double damped_J = 0.0;    // taken out by the damper at the finger, Σ (f − f')·Δx
  std::uint64_t interventions = 0;  // ticks the damper acted
  double reservoir_J() const { return input_J + returned_J - output_J - credited_J; }
};

// One tick's outcome: the force to command, and the energy to credit to the world behind the tick's pushes.
struct HandPortTick {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  double credit_J = 0.0;
};

class HandPort {
 public:
  // A validated world frame: whether the layer is on, and what the world has handed back since the last frame. The
  // first frame of a world session (or of this port) sets the baseline: a slot's running total may include what the
  // world handed an earlier owner of the slot.
  void on_plane_frame(const PlaneFrame& frame);

  bool active() const { return active_; }

  // Books the finger's displacement since the last tick, `displacement_m` (nullptr: not known, the finger was away),
  // under the force commanded then, and returns the force to command for this tick's contact force `force_N`
  // (step 1) and the credit to offer (step 2): the proxy spring holds `stored_J`; `pushing_dynamic` when the tick
  // pushed a dynamic object the world can credit. The caller hands the credit to the accumulator
  // (ImpulseAccumulator::set_last_credit) and books what it took with credit(). Inactive: force_N and 0.
  HandPortTick tick(const Eigen::Vector3d& force_N, const Eigen::Vector3d* displacement_m, bool pushing_dynamic,
                    double stored_J);
  // The device commanded its minimum output this tick (no finger, a fault): nothing held to book at the next.
  void idle();
  void credit(double credited_J);

  const HandPortBooks& books() const { return books_; }

 private:
  bool active_ = false;
  bool have_baseline_ = false;
  std::uint64_t world_session_ = 0;
  double returned_seen_J_ = 0.0;  // the world's running total at the last frame
  bool holding_ = false;          // a force was commanded at the last tick
  Eigen::Vector3d contact_N_ = Eigen::Vector3d::Zero();  // the last tick's contact force f
  Eigen::Vector3d command_N_ = Eigen::Vector3d::Zero();  // and the force commanded, f'
  HandPortBooks books_{};
};

}  // namespace impetus
