// SPDX-License-Identifier: Apache-2.0
#pragma once
// Local dynamics: the haptic side moves the touched objects between world frames (paper §6.3,
// `--coupling local`).
//
// With impulse coupling (§2.2) the finger pushes on a plane that cannot move until the next world step, so the object
// receives more momentum than it would at 1 kHz and overshoots. Here the haptic controller "calculates some part of
// the motion of the solid object" (§6.3): every dynamic object in the frame is a rigid body of the frame's state
// (centre of mass, velocity, angular velocity, inverse mass and world inverse inertia) with the contacts the world saw
// (LocalContact in common/contract/frames.h), integrated at the haptic rate from the impulse rendered so far:
//
//   at the start of each world substep h (frame.world_substep_s; every tick if unknown), the drift over h, on the
//   same grid and with the same symplectic Euler as ODE, so a sliding object ends the period where the world puts it
//   (friction applied every 1 ms instead of every 5 ms would differ by a·T_w·(h − Δt)/2 ≈ 0.06 mm per period):
//     v ← v + g·h                                               drift: gravity ...
//     for each contact n (unilateral):                          ... the supports ...
//       P = max(0, −v·n);  v ← v + P·n                          (normal impulse per unit mass)
//       a support not reached yet (LocalContact gap_m > 0: the floor or a table below a body resting on nothing) lets
//       the body approach by what is left of the gap, g = gap + u·n, within the substep: P = max(0, −v·n − g/h). The
//       body lands on it at the substep's end, as in the world; without it, a body the fingers set down over a
//       delayed link was held in the air by the model a round trip after the world's had landed, and the fingers
//       lifted the world's off the floor and threw it (docs/latency.md, the grasp)
//       a loose contact (no kContactHolds: a neighbour that can give way, world_manager/features/contact_graph.h) takes at
//       most the weight it carries, P ≤ max(0, −g·n)·h: it holds the body up but yields to the finger's push
//       v_t = v − (v·n)·n;  v ← v − min(|v_t|, μ·P)·v_t/|v_t|   ... and their Coulomb friction (cube on a floor:
//                                                                μ·g·Δt of speed per tick, as in the world)
//       a loose contact with a dynamic neighbour (LocalContact other_velocity_mps, other_inverse_mass_per_kg) is also
//       a mass the body cannot pass through: moving into it, (v − v_o)·n < 0, the two share a perfectly inelastic
//       impulse J = −(v − v_o)·n / (1/m + 1/m_o): v ← v + J/m·n, v_o ← v_o − J/m_o·n (also after each tick's push).
//       The neighbour is a free mass here (its own supports are not modelled), so the model gives way at most as
//       much as the world, the passive side; without it a 0.2 kg cube driven into the finger by a 2 kg box would be
//       sent back through the box by the finger's push while in the world both come on together.
//       a sphere's friction acts at its contact point c = −r·n from the centre: the slip is that point's velocity,
//       s = (v + ω × c)_t, and the friction impulse j (per unit mass, against s, |j| ≤ μ·P, at most what stops the
//       slip) changes both: v ← v + j, ω ← ω + m·I⁻¹·(c × j). A rolling ball (s = 0) keeps its speed, as in the
//       world; a sliding one spins up to rolling. Without it the model would brake a rolling ball at μ·g and the
//       world's ball would arrive where the model's was not yet (an object that comes to the finger).
//       a box's friction acts at the four corners of the face it rests on (the world's box–plane contacts), P/4 each:
//       the slip at corner r is (v + ω × r)_t, and its impulse j turns the box about n only (the supports hold it
//       from tipping): v ← v + j, ω ← ω + m·(n·I⁻¹·n)·(n·(r × j))·n. A box struck off-centre spins down as in the world;
//       without it the model's box spun freely, its face turned away from the finger too soon, and at a 10 Hz world
//       its yaw after an off-centre tap fell 15 % short of the 1 kHz reference's.
//       a box on a holding support (kContactHolds) also keeps each of those corners from moving into it, with a
//       unilateral impulse at the corner (v and ω both): a box pushed high on its side or on its top does not pitch
//       into the floor, as the world's corner contacts keep it, yet tips if the push lifts a side. Without it the
//       model's box pitched freely under a finger sliding over its top (1.2 mm of rim in a period at 1.7 N), and the
//       finger was let go 3 ms after the world's edge instead of at once.
//     ω otherwise free (a rolling ball keeps its spin): a turning body keeps its angular momentum L = I·ω while
//     its inertia turns with it, I ← R·I·Rᵀ each tick, and ω = I⁻¹·L (torque-free precession, as the engines have it)
//     a push later in the substep (below) meets what is left of each support's friction this substep: the tangential
//     impulse a support has given since the substep began stays within μ·P, as in the world, where a substep's
//     contact forces and the finger's push are solved together. Without it a body held against the finger on a
//     slope crept between the substeps' friction (0.05 mm a 5 ms substep at 1.9 N on 0.5 kg), and under delay the
//     replayed pushes carried it 0.5 mm away from where the world held it, so the finger pressed too little and the
//     cube slid through it in the world (docs/latency.md, "Catch")
//   each tick, before the planes are rendered:
//     u ← u + v·Δt                                              CoM displacement since the frame
//   after the force of the tick (§3.4 share J, angular share L about the CoM):
//     v ← v + J/m;  ω ← ω + I⁻¹·L                               (ω: the surface velocity friction sees, §6.2)
//     then each support's friction, from what is left of its substep's μ·P (above)
//
// A frame's state is the world's state *now* (the world integrates the impulses of the period just rendered, placed
// at the times they were rendered, world.h), so the planes are rendered at the frame's plane moved with the model:
// x ↦ x + u, normal unchanged. Frame i's plane is therefore extrapolated with the model, not interpolated from i−1
// (which would lag a period behind the object the finger is pushing).
//
// Curved planes translate, they do not rotate. A plane is §3.1's first-order picture of the surface at the nearest
// point p to the finger; it holds near p only. Carrying it rigidly about the CoM (x ↦ com + u + R·(x − com), n ↦ R·n)
// is right for a flat face, and a box's faces (ShapeTraits::flat_faces) are carried so, R the model's turn since the frame from ω:
// an off-centre push turns the face away from the finger as in the world, where a face held square would take the
// push too long and over-spin the box. It is not right for a curved surface: a sphere's surface does not move when it
// spins, yet its rotated tangent plane sweeps the finger's position at ω·L, L = the finger's distance from p along the
// plane (up to the finger's travel in a period, 25 mm at 10 Hz). With small, fast-spinning bodies this is an active
// wall: 3 g balls (I = 1.2e-7 kg·m²) roll at ~20 rad/s in the world, and a friction share at L = 1 cm adds ~200 rad/s
// per 10 N·ms, so the swept plane strikes the finger, the reaction at lever L spins the ball faster, and the swept
// planes pinch the proxy into infeasible sets (docs/hard_cases.md, case 10). For curved surfaces the
// rotation within a period is not lost: the world integrates the angular impulses, and its next frame brings the
// rotated face, blended in like §3.2's interpolation (the lag impulse coupling has for every plane). ω is still
// integrated: it gives the surface velocity friction sees (a sphere's plane is taken again at the proxy each tick
// instead, shape_planes.h). The axes of a curved body that carries them turn with it (its ends move when it spins),
// and its planes are taken again from the turned shape.
//
// Which way a wrong model errs. A model that gives way *less* than the world (a neighbour taken as immovable, a turn
// it stopped) has the finger press a plane that does not yield, and the world then hands the object momentum the
// finger never felt: energy from nowhere, as impulse coupling does. A model that
// gives way *more* than the world only lets the finger in deeper, and the frame-boundary rule below then holds the
// plane where the finger is: softer, never active. So every approximation here leans toward more give: loose
// neighbours yield, rotation is free, the tick is solved implicitly.
//
// Frame boundaries. When frame i arrives the plane the finger was feeling, C (frame i−1's plane moved by the old
// model), and the world's new plane P normally agree to within the model error (floor friction per 1 ms tick vs per
// 5 ms substep; features that change, e.g. the nearest point sliding over a sphere). Instead of jumping, the rendered
// plane blends from C to P over the period like §3.2 (weight w), both carried by the new model's pose:
//     point = P + (1 − w)·(C − P)_tangential + (1 − w_n)·((C − P)·n_P)·n_P,   normal = blend(n_C, n_P, w) (§3.2 rules)
// Passivity: if P lies toward the finger from C (the world moved the object less than the model did: a wrong model,
// e.g. an object stuck behind another the model did not know), closing that gap would push the finger out and add
// energy. w_n therefore never moves the plane past the last proxy: the gap closes only as the finger withdraws (a
// wrong model errs toward a softer object, never toward an active one). The model itself never pushes: the plane
// moves with the world's motion and with the finger's own impulse, which moves it away from the finger.
// A depth the replay revealed (below, "Delay": a new plane whose body the replay carried over the proxy, a round trip
// further on than any frame showed it) is held the same way from its first frame, and closes only by the finger's
// own withdrawal: w_n grows by at most the proxy's clearance from the plane rendered the tick before, also in the
// frames after, until it has closed. A body that moves back under the finger's push carries that plane with it, so
// the finger's spring relaxes as against any face. Closing the gap as fast as the body leaves would keep the plane at
// the proxy and the force at its height while the body moves under it: work on the body that neither hand nor spring
// gave (a cube caught over a 50 ms link was thrown back up its ramp with 0.14 J more than it came with). A gap of
// the model's own error (a body driven by a heavier neighbour than the model knows, hard case 12d) closes as the
// body makes room: there the world's body is really over the finger, and holding it would let it through.
// The model is restarted from the world's state at every frame, so a local deviation does not outlive the contact.
//
// Delay. A frame's state is the world's after it applied the report of tick a (PlaneFrame::report_tick_applied, this
// haptic session's): it holds every impulse rendered up to tick a and none after. Without delay the frame arrives
// right after tick a and the model starts from it. Over a link that holds frames and reports (a network) the frame
// arrives at a later tick b, and the servo has rendered ticks a+1 … b meanwhile; a model restarted from the frame
// alone would be the object as it was before those pushes, behind and slower than the one the finger has been
// pushing (the world gets those impulses later and then overshoots: docs/latency.md). So the model keeps a log of
// what it did each tick (the tick's length, whether it advanced, the shares it took) and, after restarting from a
// frame, replays ticks a+1 … b on the frame's state: the model the finger then feels is the world's state carried
// forward by exactly the pushes the world has not seen yet. The replayed motion is then folded into the frame's
// planes (they are moved to where the model carried them), so the blend from the plane the finger was feeling starts
// from the present. The log holds kLoggedTicks ticks (a round trip of up to two seconds); a frame whose missing ticks
// it no longer holds restarts without the replay, and is counted (replay_gaps).
//
// Allocation-free after construction; owned by the servo thread.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/plane_motion.h"
#include "haptic_controller/proxy_projection.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace impetus {

struct LocalBody {
  std::int32_t object_id = -1;
  double inverse_mass_per_kg = 0.0;
  Eigen::Matrix3d inverse_inertia_world = Eigen::Matrix3d::Zero();  // turned with the body (turn)
  Eigen::Matrix3d inertia_world = Eigen::Matrix3d::Zero();          // its inverse, where `precesses`
  bool precesses = false;  // ω follows the kept angular momentum as the body turns (header, "ω otherwise free")
  Eigen::Vector3d com_frame_m = Eigen::Vector3d::Zero();  // at the frame
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d displacement_m = Eigen::Vector3d::Zero();          // u, of the CoM since the frame
  std::array<Eigen::Vector3d, kMaxLocalContacts> contact_normal{};
  std::array<double, kMaxLocalContacts> contact_friction{};
  std::array<bool, kMaxLocalContacts> contact_holds{};  // kContactHolds: the other side holds the finger's push
  // A loose contact's dynamic neighbour as the model carries it: its velocity (from the frame, then changed by what
  // the body shares with it) and inverse mass (0: none, static or unknown).
  std::array<Eigen::Vector3d, kMaxLocalContacts> neighbour_velocity_mps{};
  std::array<double, kMaxLocalContacts> neighbour_inverse_mass_per_kg{};
  // How far each support was from the body at the frame along its normal (LocalContact::gap_m; 0: touching).
  std::array<double, kMaxLocalContacts> contact_gap_m{};
  std::uint32_t contact_count = 0;
  double sphere_radius_m = 0.0;  // > 0 for a ball (ShapeTraits::round): its supports touch it at com − r·n
  // Its shape and its axes at the frame (columns, world frame). A flat-faced body's supports touch it at the four
  // corners of the face that looks along −n (common/shape/shape.h support_corners), as the world's contacts do.
  Shape shape;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  bool rests_on_corners = false;
  // The friction of the current substep, per support: its Coulomb limit μ·P and what it has used, so a push later in
  // the substep meets the rest of it (header, "the supports ... after each tick's push").
  std::array<double, kMaxLocalContacts> friction_limit{};
  std::array<Eigen::Vector3d, kMaxLocalContacts> friction_used{};                       // a body without corners
  std::array<std::array<std::array<double, 2>, 4>, kMaxLocalContacts> corner_friction{};  // a box: per corner, per tangent
  bool touched = false;       // the finger pushed it in the last tick
  Eigen::Vector3d pushed_Ns = Eigen::Vector3d::Zero();  // Σ J since the frame (diagnostics, tests)

  bool turns = false;  // its planes are flat faces (ShapeTraits::flat_faces): they turn with it (header)
  // Its planes carry the axes of a curved body (shape_planes.h): the axes turn with it, the planes do not (they are
  // taken again from the turned shape at the proxy every tick). An end of a spinning 3 cm cylinder moves 1 mm in
  // 0.1 rad, what a 10 Hz period of 1 rad/s turns it, and a shape held square would leave it there.
  bool turns_shape = false;
  Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();  // R, the model's rotation since the frame (turning bodies)

  Eigen::Vector3d com_m() const { return com_frame_m + displacement_m; }
  // Where the model has carried a point of the frame's planes: with the CoM, and turned about it for a flat-faced
  // body (header, "Curved planes translate").
  Eigen::Vector3d carry_point(const Eigen::Vector3d& x_m) const {
    return turns ? Eigen::Vector3d(com_m() + turn * (x_m - com_frame_m)) : Eigen::Vector3d(x_m + displacement_m);
  }
  Eigen::Vector3d carry_normal(const Eigen::Vector3d& normal) const {
    return turns ? Eigen::Vector3d(turn * normal) : normal;
  }
  // Where the model has turned an axis of the body's shape.
  Eigen::Vector3d carry_axis(const Eigen::Vector3d& axis) const {
    return turns || turns_shape ? Eigen::Vector3d(turn * axis) : axis;
  }
};

class LocalDynamics final : public PlaneMotion {
 public:
  // Ticks the delay log holds: a frame replays the round trip, 2d, so 2048 ticks of 1 ms cover the link delays the
  // in-process link takes (up to 1 s each way) with room for a late world step.
  static constexpr std::size_t kLoggedTicks = 2048;
  // Shares a logged tick holds: a finger's own (at most one per active constraint and the plane it slides on) and
  // one other endpoint's of the same controller; more are counted (unlogged_shares).
  static constexpr std::size_t kLoggedSharesPerTick = 2 * (kMaxActiveConstraints + 1);

  // Serves `haptic_session` (whose reports a frame's report_tick_applied must name for the replay). Allocates the
  // delay log; nothing after.
  explicit LocalDynamics(std::uint64_t haptic_session = 0);

  // The servo's tick about to be rendered (its report's tick): stamps the log.
  void note_tick(std::uint64_t tick) { tick_ = tick; }

  // PlaneMotion: the steps below in the servo's order.
  void on_frame(const PlaneFrame&, const PlaneFrame& frame, const PlaneSet* displayed,
                const Eigen::Vector3d& proxy_m) override {
    on_plane_frame(frame, displayed, proxy_m);
  }
  void planes_for_tick(double w, double dt_s, bool stale, const Eigen::Vector3d& pivot_m, PlaneSet& out) override {
    log_tick(stale ? 0.0 : dt_s);
    if (!stale) advance(dt_s);  // a stale world: the model holds still
    render(w, pivot_m, out);
  }
  void take_shares(const ImpulseShare* shares, int count) override {
    for (int k = 0; k < count; ++k) {
      if (!shares[k].dynamic) continue;
      log_share(shares[k]);
      apply_impulse(shares[k].object_id, shares[k].impulse_Ns, shares[k].angular_impulse_Nms);
    }
  }
  double frame_disagreement_m() const override { return last_model_error_m(); }

  // A new world frame at the servo: restart every body from the frame's state and remember, per plane, the plane
  // the finger was feeling (`displayed`: the last tick's planes, or nullptr) to blend from. `proxy_m` is the proxy of
  // that tick, where last_model_error_m is measured.
  void on_plane_frame(const PlaneFrame& frame, const PlaneSet* displayed, const Eigen::Vector3d& proxy_m);

  // Advances every body by dt_s (drift, contacts, pose), before the planes of a tick are rendered.
  void advance(double dt_s);

  // The finger's share of this tick on `object_id` (reaction, N·s, and angular about the displayed CoM, N·m·s).
  void apply_impulse(std::int32_t object_id, const Eigen::Vector3d& impulse_Ns,
                     const Eigen::Vector3d& angular_impulse_Nms);

  // The frame's planes at blend weight w, carried by the bodies' poses; velocities and centres of mass are the
  // model's. `proxy_m` is the last tick's proxy (the passivity bound of the blend). Clears the bodies' touched flags
  // (apply_impulse sets them again).
  void render(double w, const Eigen::Vector3d& proxy_m, PlaneSet& out);

  // The share of the explicit contact force the touched bodies can take within one tick (implicit contact, ≤ 1).
  // The force k·d + b·ḋ assumes the objects stand still during the tick, but a body of mass m gives way by f·Δt²/m
  // within it, and the model applies the reaction only after the tick. The error e of the finger–body contact then
  // follows e_{j+1} = (1 − a − c)·e_j + c·e_{j−1}, a = kΔt²/m, c = bΔt/m, which has a root below −1 once m is under
  // about bΔt + kΔt²/2 (6 g at 2 kN/m, 5 N·s/m, 1 kHz): the force flips sign every tick and pumps energy into the
  // object (hard case 10's 3 g balls). Solving the tick implicitly, f = (k·d + b·ḋ)/(1 + a + c), keeps both roots
  // inside the unit circle for any mass; on a 1 kg body it lowers the force by 0.7 %. 1/m is the contact's effective
  // inverse mass along `force_N` at the proxy (translation and rotation), the touched bodies' weighted by their shares
  // of the reaction (static planes: 0).
  double yield_scale(const PlaneSet& planes, const ProxySolution& contact, const Eigen::Vector3d& force_N,
                     double stiffness_Npm, double damping_Nspm, double dt_s) const override;

  const LocalBody* find(std::int32_t object_id) const;
  std::uint32_t body_count() const { return body_count_; }

  // At the last frame: the largest difference, at the finger's proxy, between the plane the finger was feeling and
  // the world's new plane, over touched objects (m): how far the world and the model disagreed.
  double last_model_error_m() const { return last_model_error_m_; }
  // Ticks replayed after the last frame (the delay the model caught up on), and frames that could not be replayed.
  std::uint64_t last_replayed_ticks() const { return last_replayed_ticks_; }
  std::uint64_t replay_gaps() const { return replay_gaps_; }
  std::uint64_t unlogged_shares() const { return unlogged_shares_; }

  void reset() { body_count_ = 0; plane_count_ = 0; }

 private:
  LocalBody* find_mutable(std::int32_t object_id);
  void apply_drift(LocalBody& body, double h_s) const;
  // Coulomb friction of a box's support with normal n at the corners of the face it rests on (header), `limit` the
  // support's friction impulse per unit mass, μ·P.
  static void apply_box_friction(LocalBody& body, const Eigen::Vector3d& n, double limit,
                                 std::array<std::array<double, 2>, 4>& accumulated);
  // After a push within a substep: each support's friction takes what is left of its substep's limit.
  static void hold_after_push(LocalBody& body);
  // The four corners of the face a box rests on against a support of normal n, from the centre of mass (world frame).
  static std::array<Eigen::Vector3d, 4> support_corners(const LocalBody& body, const Eigen::Vector3d& n);
  // A holding support keeps each of those corners from moving into it (header); returns the normal impulse it took,
  // per unit mass.
  static double hold_box_corners(LocalBody& body, const Eigen::Vector3d& n);
  // The inelastic share with moving loose neighbours (header): after the drift and after each push.
  static void share_with_neighbours(LocalBody& body);

  // The delay log (header, "Delay"): one record per rendered tick, in a ring.
  struct LoggedShare {
    std::int32_t object_id = -1;
    Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();
  };
  struct LoggedTick {
    std::uint64_t tick = 0;
    double advanced_s = 0.0;  // what advance() was given (0: a stale world, the model held still)
    std::uint32_t share_count = 0;
    std::array<LoggedShare, kLoggedSharesPerTick> shares{};
  };
  void log_tick(double advanced_s);
  void log_share(const ImpulseShare& share);
  // Replays the logged ticks after `applied_tick` on the restarted bodies and folds their motion into the frame's
  // planes; returns the ticks replayed.
  std::uint64_t catch_up(std::uint64_t applied_tick);

  struct PlaneBlend {
    Eigen::Vector3d from_point_m = Eigen::Vector3d::Zero();  // C
    Eigen::Vector3d from_normal = Eigen::Vector3d::UnitZ();
    double normal_weight = 0.0;  // w_n: how much of the normal offset has been closed (never decreases)
    bool hold_normal = false;    // P is toward the finger from C: close no further than the proxy
    bool revealed = false;       // the held gap is a depth the replay revealed: only the finger's withdrawal closes it
    // The plane rendered the tick before (world frame): the finger's clearance from it is what w_n may close.
    Eigen::Vector3d last_point_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d last_normal = Eigen::Vector3d::UnitZ();
  };

  PlaneFrame frame_{};  // the planes of the current frame (P)
  std::uint32_t plane_count_ = 0;
  std::array<PlaneBlend, kMaxPlanes> blends_{};
  std::array<int, kMaxPlanes> body_of_plane_{};  // index into bodies_, −1 for static planes
  std::array<LocalBody, kMaxPlanes> bodies_{};
  std::uint32_t body_count_ = 0;
  Eigen::Vector3d gravity_mps2_ = Eigen::Vector3d::Zero();
  double substep_s_ = 0.0;       // the world's drift grid; 0: every tick
  double elapsed_s_ = 0.0;       // model time since the frame
  double next_drift_s_ = 0.0;    // start of the next substep whose drift is still to apply
  double last_model_error_m_ = 0.0;

  std::uint64_t haptic_session_ = 0;
  std::uint64_t tick_ = 0;
  std::vector<LoggedTick> log_;   // kLoggedTicks records, a ring
  std::size_t log_next_ = 0;      // where the next record goes
  std::size_t log_size_ = 0;
  std::uint64_t overwritten_tick_ = 0;  // the newest tick the ring has dropped
  std::uint64_t last_replayed_ticks_ = 0;
  std::uint64_t replay_gaps_ = 0;
  std::uint64_t unlogged_shares_ = 0;
};

}  // namespace impetus
