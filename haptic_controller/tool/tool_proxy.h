// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 6-DoF god-object (docs/tool.md): the tool's proxy is a massless copy of the tool, held outside every object by
// the contacts of tool_contacts.h and pulled toward the device's grip by a 6-DoF spring–damper, the coupling. The
// wrench the coupling puts on the grip is what the hand feels; its reaction, contact by contact, is what the objects
// receive, integrated tick by tick (paper §3.4 in 6 DoF).
//
// Each tick, with e = (x_p − x_d, θ) the proxy's displacement from the grip (θ the rotation vector of the turn from
// the grip to the proxy):
//  1. Where the tool can go straight from the proxy to the grip touching nothing (ToolContacts::path_clear), the
//     proxy is the grip and there is no wrench.
//  2. Else the proxy moves to the pose nearest the grip that the contacts allow, in the springs' metric
//     K = diag(k·I, k_r·I): the move q minimises ½(q − q*)ᵀK(q − q*), q* = −e, under the linearised contacts
//     gap_i + a_i·q ≥ 0, a_i = [n_i; r_i × n_i] for a contact pushing the tool along n_i at lever r_i from the proxy's
//     centre; a small convex QP solved exactly (contact_qp.h), again from the moved pose while a contact acts and the
//     pass moved the tool (the turn and curved surfaces are linearised). Its multipliers λ_i ≥ 0 carry the spring's
//     wrench: K·e = Σ λ_i·a_i.
//  3. The damper B = diag(b·I, b_r·I) adds B·(e − e_prev)/Δt, and the sum is projected onto the cone of the acting
//     contacts' pushes, Σ μ_i·a_i with μ_i ≥ 0: a contact pushes, it never pulls.
// The wrench on the grip is Σ μ_i·a_i (its torque carried to the grip's centre), exactly the sum of the contacts'
// pushes, so what the world receives equals what the hand feels.
//
// A tool with weight w (ToolShape::weight_N, acting at its centre of mass c) adds the potential −wᵀq to the proxy's
// energy: the proxy's rest pose with nothing in the way is the grip moved by the sag K⁻¹·W, W = [w; (c − x_p) × w],
// and every step above runs toward that goal pose instead of the grip. The contacts then carry the spring's wrench
// less the weight (a tool resting on a table presses it with its weight, and the hand feels none of it), and the hand
// feels the contacts' pushes plus the weight (a tool held in the air weighs w in the hand). The weight is a constant
// force, whose work is a potential: it adds no energy to the loop.
//
// Stability (docs/tool.md): a massless proxy held by rigid unilateral constraints is passive, and the sampled
// coupling then needs the device's physical damping above K·T/2 per DoF (Colgate & Schenkel; Adams & Hannaford's
// virtual coupling): b > k·T/2 and b_r > k_r·T/2. The virtual damper B adds the damping a hand's grip lacks in turning.
//
// Frames: world, SI; a pose is the grip's (its centre and orientation); torques about the grip's centre. Owned by
// the servo thread; allocation-free, no exceptions after construction.

#include "common/contract/frames.h"
#include "common/contract/tool.h"
#include "common/shape/shape.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/tool/contact_qp.h"
#include "haptic_controller/tool/tool_contacts.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>

namespace impetus {

struct ToolResult {
  BodyPose proxy;  // the proxy's grip pose
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();    // on the grip, after the limits
  Eigen::Vector3d torque_Nm = Eigen::Vector3d::Zero();  // on the grip about its centre, after the limits
  // Of them, the tool's weight (after the limits' scale): the part the objects do not receive.
  Eigen::Vector3d weight_force_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d weight_torque_Nm = Eigen::Vector3d::Zero();
  double scale = 1.0;        // the limits' scale of the wrench (1: within them)
  int constraints = 0;       // contacts the last pass considered
  int active = 0;            // of them, pushing (λ > 0)
  int passes = 0;            // QP solves this tick (0: the way was clear)
  int gathers = 0;           // of them, those that gathered the contacts afresh (tool_contacts.h)
  int iterations = 0;        // the QP's contacts added and dropped, summed over the passes
  bool converged = true;     // every pass solved its QP (contact_qp.h)
  bool fault = false;        // a non-finite grip or result: no wrench, the proxy kept
};

// A contact's push on the tool in the last solve (after the limits' scale).
struct ToolContactForce {
  std::int32_t plane = -1;
  std::int32_t object_id = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the push on the tool
  Eigen::Vector3d tool_point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_point_m = Eigen::Vector3d::Zero();
  double force_N = 0.0;  // λ ≥ 0
};

// Passes a tick makes at most, and the move below which a pass is the last (m): the next would change the proxy by
// the move's square over the surfaces' radius of curvature, far below it.
inline constexpr int kMaxToolPasses = 4;
inline constexpr double kToolSettled_m = 1e-7;

struct ToolCounters {
  std::uint64_t solves = 0;
  std::uint64_t faults = 0;
  std::uint64_t clamps = 0;          // wrenches scaled to the limits
  std::uint64_t pinches = 0;         // passes whose contacts, as linearised, no move satisfied: solved going no deeper
  std::uint64_t unconverged = 0;     // passes whose QP did not converge even so (contact_qp.h): the proxy stayed
};

class ToolProxy {
 public:
  // Throws std::invalid_argument for an unusable tool shape (ToolContacts), weight (finite, mass ≥ 0) or coupling
  // (stiffnesses > 0, dampings and limits ≥ 0 / > 0, all finite), naming the field.
  ToolProxy(const ToolShape& tool, const ToolCoupling& coupling);

  // Puts the proxy on the grip, with no history (the device attached, a session restart).
  void reset(const BodyPose& grip);
  // The objects' poses jumped (a world frame that disagrees with the local model, or a new world): the next solve
  // holds the proxy inside whatever it then overlaps instead of pushing it out at once, as at a session start
  // (held_ below), and lets it out over `release_s` of solve time (infinity: only as the tool withdraws).
  // limit_hold then bounds what object `object_id` may hold to `most_m` (the most its jump can have moved any of its
  // points toward the tool); an object without a bound holds all of its overlap.
  void hold_overlaps(double release_s) {
    hold_next_ = true;
    hold_release_s_ = release_s;
    hold_limit_count_ = 0;
  }
  void limit_hold(std::int32_t object_id, double most_m) {
    if (hold_limit_count_ < static_cast<int>(hold_limits_.size())) {
      hold_limits_[static_cast<std::size_t>(hold_limit_count_++)] = {object_id, most_m};
    }
  }

  // One tick: the grip at `grip`, dt_s (> 0) after the last; `planes` the objects near the tool this tick.
  const ToolResult& solve(const PlaneSet& planes, const BodyPose& grip, double dt_s);

  const ToolResult& result() const { return result_; }
  const ToolContactForce* contact_forces() const { return forces_.data(); }
  int contact_force_count() const { return force_count_; }

  // The reaction of the last solve per object, as impulses over its dt_s: linear, and angular about the object's
  // centre of mass accumulated contact by contact ((object point − centre) × J). Each share's credit_J is the hand's
  // work behind it: J·v at each contact, v the grip's velocity there over the tick, where positive.
  const ImpulseShare* shares() const { return shares_.data(); }
  int share_count() const { return share_count_; }

  const ToolContacts& contacts() const { return contacts_; }
  const ToolCoupling& coupling() const { return coupling_; }
  const ToolCounters& counters() const { return counters_; }

 private:
  // One pass: gathers the contacts at the proxy now, solves the QP toward `target` and moves the proxy.
  // One solve of the QP toward `target` from the proxy now, which it moves; returns the move (δx, δθ). `gather`:
  // gathers the contacts within the move's reach first (else uses those gathered or refreshed last); `mark_held`:
  // the first pass after a session start or a jump (hold_overlaps), whose overlapped objects are held.
  Vector6d pass(const PlaneSet& planes, const Vector6d& target, bool gather, bool mark_held);
  // How deep the proxy may stay in `object_id` (m; 0: not held).
  double allowance_m(std::int32_t object_id) const;
  void hold(std::int32_t object_id, double depth_m);
  // After the passes: each held object's allowance shrinks to the depth the moved proxy still has in it.
  void release_held(const Vector6d& last_move);
  // The damper's part, and the pushes (forces_) that carry the wrench: step 3 of the header.
  void damp(const Vector6d& displacement_now, double dt_s);
  void share_reaction(const PlaneSet& planes, const BodyPose& grip, double dt_s);
  void zero_output();
  // Where the proxy rests with nothing in the way: the grip moved by the weight's sag (the header).
  BodyPose goal_of(const BodyPose& grip) const;
  // The wrench on the grip: the contacts' pushes (forces_) and the weight at the proxy's centre of mass, scaled to
  // the limits; the result's proxy, wrench and scale. False for a non-finite one (nothing set).
  bool set_wrench(const BodyPose& grip);

  ToolContacts contacts_;
  ToolCoupling coupling_;
  Eigen::Vector3d weight_N_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_of_mass_m_ = Eigen::Vector3d::Zero();  // in the grip's frame
  BodyPose proxy_;
  BodyPose grip_;  // at the last solve
  bool started_ = false;
  bool failed_ = false;  // a pass of this solve found no move (pass())
  bool hold_next_ = true;
  double hold_release_s_ = std::numeric_limits<double>::infinity();
  // Objects the proxy overlapped when it started (the session's first solve) or when their poses jumped
  // (hold_overlaps): the proxy is not thrown out of them, which would be a kick nobody's push caused. Each keeps the
  // depth the proxy had in it then, its allowance: the proxy goes no deeper, and the allowance shrinks to the depth
  // the proxy still has as it leaves, and over the release time at a steady rate (a frame's correction reaches the
  // hand as a ramp over the world period, as the point finger's plane blends over it, local_dynamics.h). At a
  // session start it is released only by leaving (the point finger's god-object, god_object.h). An object that moves
  // in farther than its allowance still pushes the proxy.
  struct Held {
    std::int32_t object_id = -1;
    double depth_m = 0.0;
    double release_mps = 0.0;  // how fast the allowance shrinks by itself
  };
  std::array<Held, kMaxServoPlanes> held_{};
  int held_count_ = 0;
  std::array<Held, kMaxServoPlanes> hold_limits_{};  // depth_m: the most object_id may hold at the next mark
  int hold_limit_count_ = 0;
  Vector6d previous_displacement_ = Vector6d::Zero();
  Eigen::Vector3d grip_velocity_mps_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d grip_angular_velocity_radps_ = Eigen::Vector3d::Zero();
  ToolReach gathered_{};  // the reach the contacts were last gathered for
  std::array<ContactQpRow, kMaxToolConstraints> rows_{};
  std::array<double, kMaxToolConstraints> lambda_{};
  std::array<ContactQpRow, kMaxToolConstraints> cone_rows_{};  // the acting contacts' pushes, for the damper's part
  std::array<double, kMaxToolConstraints> mu_{};
  std::array<int, kMaxToolConstraints> acting_{};
  std::array<ToolContactForce, kMaxToolConstraints> forces_{};
  int force_count_ = 0;
  std::array<ImpulseShare, kMaxServoPlanes> shares_{};
  int share_count_ = 0;
  ToolResult result_{};
  ToolCounters counters_{};
};

}  // namespace impetus
