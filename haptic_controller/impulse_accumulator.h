// SPDX-License-Identifier: Apache-2.0
#pragma once
// Impulse integration (paper §3.4, docs/architecture.md §1.2 step 5): the user's force on the world is the reaction
// −f_j of the force rendered on the finger. Each tick it is shared among the active constraints: each plane takes
// the part of the reaction along its own normal (least squares over the active normals, pushes only), and what lies
// in no normal (friction along the surface) is shared in proportion to the multipliers (the normal load each plane
// carries: a finger pressing a cube onto the floor loads only the cube's plane, so the cube gets the push and passes
// it on to the floor in the world's own simulation). An object can only be pushed along its own normal: sharing the
// whole vector by multipliers lifted a ball touched at its side by the finger's press on the floor beside it (hard
// case 10). Where the planes face each other the split would be a squeeze (pushes that cancel on the finger and only
// drive the objects apart, ill-conditioned as the planes turn opposite); then the multipliers share the whole vector.
// Accumulated per object exactly, tick by tick:
//     impulse_Ns          += J_k (the share of −f_k·Δt)
//     angular_impulse_Nms += (contact − com) × J_k      (contact = the proxy, com interpolated; through the centre
//                                                        for a sphere's normal part, contact_plane.h)
// rather than the paper's single F_i at one point p_i. Planes without kPlaneDynamic or kPlaneDeformable (floor, fixed
// objects) feed report.static_impulse_Ns. Each entry also records where and when its surface was pressed
// (ObjectImpulse::press_*), which a deformable object dents by.
//
// The report holds running totals (ObjectImpulse in common/contract/frames.h). When all kMaxImpulseEntries entries are
// in use, an entry whose last_tick ≤ the world's report_tick_applied (for this haptic session) is final — the world has
// applied all of it — and is reused for the new object with a new epoch (a session-wide counter, so an object's epoch
// changes at every re-allocation). If no entry is final the share is kept in a dropped total and counted; nothing
// throws or allocates.
//
// The totals count against one world session (report().world_session, docs/architecture.md §6: impulse rendered ==
// impulse applied across a restart of either side). A frame of another world session — a restarted world — starts them
// afresh: every entry and the static total are moved to the abandoned total, so the new world, which starts from its
// scene, is given only what is rendered against its own frames. Invariant:
//     Σ entries + static + evicted + dropped + abandoned == Σ −f·Δt rendered.
//
// Each entry also carries the energy the hand put in behind its impulse (ObjectImpulse::hand_input_J): each tick, its
// share times the finger's velocity over the tick before (report().finger_m, which the servo sets before add()), where
// positive, so the world can keep what it receives within what the hand put in.
//
// Each entry also carries the first moments Σ impulse_k·t_k (t_k = report().haptic_time_s, which the servo sets before
// add()), so the world can place the impulse in time (local coupling, world.h). The shares of the last add() are kept
// for the local model (local_dynamics.h), which moves the touched objects tick by tick.
//
// Owned by the servo thread.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/proxy_projection.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace impetus {

// One object's share of the reaction in the last tick.
struct ImpulseShare {
  std::int32_t object_id = -1;
  bool dynamic = false;
  Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();  // about the plane's com_m
  double yielding_Ns = 0.0;  // a deformable plane's push beyond yield (ObjectImpulse::press_Ns's part), else 0
  double credit_J = 0.0;     // the energy this share credited to its entry's hand_input_J
  ObjectImpulse* entry = nullptr;  // its entry in the report (nullptr: static, or dropped)
};

class ImpulseAccumulator {
 public:
  // The report names `endpoint` (the finger these totals belong to) of `haptic_session`.
  explicit ImpulseAccumulator(std::uint64_t haptic_session, EndpointId endpoint = 0);

  // Learns how far the world has applied our reports (eviction rule), and starts the totals afresh for a frame of a
  // new world session.
  void on_plane_frame(const PlaneFrame& frame);

  // Adds the reaction of one tick: `force_on_finger_N` rendered for `dt_s` at haptic tick `tick` (≥ 1). With no
  // active constraint the force must be zero (nothing touched); a nonzero force then is kept in the dropped total.
  void add(const PlaneSet& planes, const ProxySolution& contact, const Eigen::Vector3d& force_on_finger_N, double dt_s,
           std::uint64_t tick);

  // Adds the reaction of one tick already shared out (a tool's contacts, tool/tool_proxy.h): each share's impulse and
  // angular impulse about its object's centre, its credit_J the hand's work behind it, booked as add() books its own
  // (no press: a tool does not dent a deformable surface yet, whose share goes to the static total).
  void add_shares(const ImpulseShare* shares, int count, std::uint64_t tick);

  HapticReport& report() { return report_; }
  const HapticReport& report() const { return report_; }

  const Eigen::Vector3d& total_impulse_Ns() const { return total_Ns_; }      // Σ −f·Δt rendered
  const Eigen::Vector3d& evicted_impulse_Ns() const { return evicted_Ns_; }  // totals of entries reused since
  const Eigen::Vector3d& dropped_impulse_Ns() const { return dropped_Ns_; }  // never reported (table full)
  // Rendered against a world session that ended before applying it (objects and static geometry).
  const Eigen::Vector3d& abandoned_impulse_Ns() const { return abandoned_Ns_; }
  std::uint64_t dropped_shares() const { return dropped_shares_; }

  // Whether the last add() pushed a dynamic object that has an entry (a push the world can credit energy to).
  bool pushed_dynamic() const;
  // Makes the energy the last add() credited to the world behind its pushes on dynamic objects `energy_J` in all, in
  // place of Σ max(0, J_k·v_k), shared in proportion to |J_k| (the passivity layer's hand, hand_port.h, decides how
  // much). Returns what it credited: 0 when the last add() pushed no dynamic object with an entry.
  double set_last_credit(double energy_J);

  // The shares of the last add(), one per active constraint (empty when nothing was pushed).
  const ImpulseShare* last_shares() const { return last_shares_.data(); }
  int last_share_count() const { return last_share_count_; }

 private:
  ObjectImpulse* entry_for(std::int32_t object_id);
  // Books a share into the report: its object's entry (impulse, angular impulse, their first moments in time, the
  // hand's credit, the tick), or the static total for a body neither dynamic nor `deformable`; dropped and counted
  // when no entry is left. Sets share.entry (nullptr unless booked) and zeroes the credit of an unbooked share.
  ObjectImpulse* book(ImpulseShare& share, bool deformable, std::uint64_t tick);

  HapticReport report_{};
  std::uint64_t applied_tick_ = 0;
  bool applied_this_session_ = false;
  std::uint32_t epoch_counter_ = 0;
  Eigen::Vector3d total_Ns_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d evicted_Ns_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dropped_Ns_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d abandoned_Ns_ = Eigen::Vector3d::Zero();
  std::uint64_t dropped_shares_ = 0;
  std::array<ImpulseShare, kMaxServoPlanes> last_shares_{};
  int last_share_count_ = 0;
  // The tick and finger position of the last add(): the next add() pairs its force with the displacement since.
  std::uint64_t hand_tick_ = 0;
  Eigen::Vector3d hand_finger_m_ = Eigen::Vector3d::Zero();
};

}  // namespace impetus
