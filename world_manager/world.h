// SPDX-License-Identifier: Apache-2.0
#pragma once
// The virtual world of the world manager: a Scene on a rigid-body engine, stepped once per world period T_w
// (docs/architecture.md §1.1): the report's impulses through the ledger to the coupling, engine substeps, the planes.
//
// Threading and ownership: a World owns its engine (the scene's physics.engine, engine/engine_registry.h) and its
// coupling strategy (couplings/) and is used from one thread. The process must have called prepare_engines()
// (engine/engine_registry.h) before constructing one. Runs are bitwise reproducible per World even when
// several Worlds live in one process (tests).
//
// Units SI, world frame right-handed with z up; object ids are scene indices, the floor is scene.floor_object_id().

#include "common/contract/frames.h"
#include "common/spidar/geometry.h"
#include "world_manager/scene.h"
#include "world_manager/couplings/coupling.h"
#include "world_manager/deform/deformable_surface.h"
#include "world_manager/engine/rigid_body_engine.h"
#include "world_manager/features/feature_extractor.h"
#include "world_manager/impulse_ledger.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace impetus {

struct WorldOptions {
  Coupling coupling = Coupling::impulse;
  std::optional<double> world_rate_hz;  // overrides scene.physics.world_rate_hz (--rate)
  // Position coupling's penalty k_p and damping; default: the scene's haptic stiffness and damping, so both couplings
  // see the same surface.
  std::optional<double> position_stiffness_Npm;
  std::optional<double> position_damping_Nspm;
  // Published in every frame so the haptic side notices a restarted world; must be nonzero. Nodes pass
  // new_session_id() (common/runtime/process.h), tests a constant.
  std::uint64_t world_session = 1;
  // The largest force a controller's device renders, N (the SPIDAR's, common/spidar/geometry.h): no report may bring
  // a step more impulse than that force could in the world time since the endpoint's last applied report (take_report).
  double report_force_limit_N = SpidarGeometry{}.max_force_N;
  // The passivity layer on the impulse port (couplings/passivity_layer.h): the energy the couplings give a body never
  // exceeds what the hands put in. Off: the paper's couplings exactly as the paper has them. The port's books are kept
  // either way. Off by default: it removes impulse and position coupling's energy gains (docs/latency.md) but, as the
  // haptic side does not yet learn what it withheld, a finger can end up inside an object it could not push back.
  bool passivity = false;
};

class World {
 public:
  // Validates the options (throws std::invalid_argument), builds the engine and the coupling. Keeps its own copy of
  // the scene.
  World(const Scene& scene, const WorldOptions& options);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // One world step (docs/architecture.md §1.1) for every endpoint slot at once. `reports[k]` is the newest report of
  // slot k (nullptr: none yet, or none new — the slot keeps its last finger); the transport has validated them. Each
  // report's new impulses go to the coupling (only those counted against this world's session), the engine advances by
  // T_w in the scene's substeps, and each slot gets a frame of the planes around its proxy. A slot taken over by
  // another (haptic session, endpoint) starts afresh. At most kMaxEndpoints slots (std::invalid_argument otherwise);
  // the returned frames, one per slot, stay valid until the next step.
  std::span<const PlaneFrame> step(std::span<const HapticReport* const> reports);
  // The same with a single endpoint slot: the one-finger trial.
  const PlaneFrame& step(const HapticReport* report) { return step(std::span<const HapticReport* const>(&report, 1))[0]; }

  // Before a step: the world's real-time clock skipped `count` steps' worth of wall time since the last (a stall;
  // never in lockstep). Reports rendered over that time bring no more than the steps simulated (take_report).
  void note_skipped_steps(std::uint64_t count) { stalled_s_ += static_cast<double>(count) * period_s_; }

  const Scene& scene() const { return scene_; }
  Coupling coupling() const { return options_.coupling; }
  double world_period_s() const { return period_s_; }
  double time_s() const { return time_s_; }
  // The haptic session time (the haptic side's clock) of the newest report that endpoint slot 0 applied, at the start
  // of the last step; NaN before any. Paired with time_s() − T_w, the world time that step started at, it puts the
  // world and the finger on one clock (the world log's haptic_time_s; scripts/impetus_py/logs.py).
  double last_report_haptic_time_s() const {
    return endpoints_.empty() || endpoints_[0].last_report_session == 0 ? std::numeric_limits<double>::quiet_NaN()
                                                                         : endpoints_[0].last_report_time_s;
  }
  std::uint64_t steps_taken() const { return steps_taken_; }
  // The frame of endpoint slot `slot` after the last step (slot 0 before any step: the frame header alone).
  const PlaneFrame& frame(std::size_t slot = 0) const { return frames_[slot]; }
  // The slots the last step served.
  std::size_t endpoint_slots() const { return slots_used_; }
  // Objects the engine took out of the simulation after the solver threw them out of range (RigidBodyEngine::escaped).
  const std::vector<std::size_t>& escaped() const;
  // Pairs the scene placed inside each other by more than kStartOverlap_m, as the engine found them at the start (the
  // solver pushes them apart on the first steps: a sphere below the floor leaves it at about 0.5 m/s).
  const std::vector<RigidBodyEngine::Overlap>& start_overlaps() const { return start_overlaps_; }
  // Deeper than any resting contact sinks (the contact spring's give under a body's weight is microns), shallower
  // than a placement mistake a user would notice.
  static constexpr double kStartOverlap_m = 1e-4;
  // The longest link round trip a report's measure is taken at: twice the in-process delay line's 1 s one way; a
  // longer measure (a stalled servo's) widens the reach no further.
  static constexpr double kMaxRoundTrip_s = 2.0;

  // Whether dynamic object `id` sleeps (scene physics.auto_disable): at rest, not simulated until something wakes it.
  bool asleep(std::size_t id) const { return engine_->asleep(id); }
  // The dynamic objects the last step simulated, ascending: what the step cost grows with (RigidBodyEngine::moved).
  std::span<const std::size_t> simulated() const { return engine_->moved(); }

  // Object-steps simulated since the start: Σ over steps of simulated().size().
  std::uint64_t simulated_object_steps() const { return simulated_object_steps_; }
  // The deepest any dynamic object has been into the floor at the end of a world step since the start (m; 0 without
  // a floor or contact). What the haptic side and the logs see of ODE's penetration, which grows with the substep
  // length: a body arriving at speed v sinks up to v·h before the substep that finds its contact.
  double floor_penetration_max_m() const { return floor_penetration_max_m_; }

  // State of every scene object after the last step (static ones never change).
  std::span<const ObjectState> states() const { return states_; }
  // Impulse the world applied to object `id` in the last step, and since the start (N·s, N·m·s). In position coupling
  // this is the penalty force times the period.
  const Eigen::Vector3d& step_impulse_Ns(std::size_t id) const { return applied_.step_Ns(id); }
  const Eigen::Vector3d& total_impulse_Ns(std::size_t id) const { return applied_.total_Ns(id); }
  const Eigen::Vector3d& total_angular_impulse_Nms(std::size_t id) const { return applied_.total_angular_Nms(id); }
  // Impulse on object `id` taken from the reports of one endpoint of one haptic session, since it first reported
  // (N·s; the ledger's differences, summed): per endpoint, what the world applied of what it rendered. Zero under
  // position coupling, which applies a penalty from the sampled finger instead.
  Eigen::Vector3d applied_by(const CounterOwner& owner, std::size_t id) const;
  // Every (haptic session, endpoint) that has had impulse applied, in order.
  std::vector<CounterOwner> impulse_owners() const;
  // Reaction into static geometry reported by the haptic side (cumulative over all its sessions), N·s.
  const Eigen::Vector3d& total_static_impulse_Ns() const { return total_static_impulse_Ns_; }
  // Report entries ignored because their object id was out of range or their numbers not finite.
  std::uint64_t rejected_entries() const { return rejected_entries_; }
  // Reports whose impulse exceeded what a device could render in the world time they cover, and the impulse cut
  // from them (N·s, Σ|ΔJ| over their entries): never applied, counted here (a rogue or corrupted report; a stalled
  // world's backlog).
  std::uint64_t clipped_reports() const { return clipped_reports_; }
  double clipped_impulse_Ns() const { return clipped_impulse_Ns_; }
  // Reports whose totals count against another world session (HapticReport::world_session): their finger is used,
  // their impulses are not.
  std::uint64_t foreign_reports() const { return foreign_reports_; }

  // The yielding top face of deformable object `id` (scene "deformable"), or nullptr for any other object. Pressed by
  // the reports' press moments (impulse rule) or the sampled fingers (penetration rule) and yielded once per step,
  // after the engine; the frames carry its surface under each proxy (kPlaneDeformable).
  const DeformableSurface* deformable(std::size_t id) const {
    return id < surfaces_.size() ? surfaces_[id].get() : nullptr;
  }

  // The impulse port's energy books per dynamic object and their sum (couplings/passivity_layer.h).
  const PassivityLayer& port() const { return *port_; }

  // Kinetic + gravitational potential energy of the dynamic objects (J), potential measured from the origin.
  double mechanical_energy_J() const;

 private:
  // What the world keeps per endpoint slot between steps.
  struct Endpoint {
    std::uint64_t haptic_session = 0;  // the (session, endpoint) its reports came from; 0: none yet
    EndpointId endpoint = 0;
    FingerState finger;        // the sampled finger: position coupling's penetration
    ReachQuery plane_query;    // where planes are extracted: the proxy, reach widened to cover the finger
    bool plane_query_known = false;  // a finger was reported in this session: plane_query is where it was last
    FeatureMemory plane_faces; // the face of each object the plane query (the proxy) met, step to step
    // The haptic time of the previous report applied: the impulses of the next one were rendered after it.
    std::uint64_t last_report_session = 0;
    double last_report_time_s = 0.0;
    std::uint64_t last_report_tick = 0;
    double last_applied_world_time_s = 0.0;  // the world time its previous report was applied at (same session)
    double stalled_at_last_applied_s = 0.0;  // stalled_s_ when its previous report was applied (take_report)
  };

  void take_finger(Endpoint& endpoint, const HapticReport& report);
  void take_report(Endpoint& endpoint, const HapticReport& report);
  // Reads the state of the dynamic objects in `moved` (static ones are set once, sleeping ones do not change), and
  // after a step (`stepped`) their mean acceleration over it.
  void refresh_states(std::span<const std::size_t> moved, bool stepped);
  void publish(std::size_t slot, const HapticReport* applied_report);
  // The passivity layer's stage 3 (couplings/passivity_layer.h): each object's unspent budget back to the endpoints
  // whose reports pushed it this step, shared by their part of its impulse |ΔJ|.
  void hand_back_unspent();

  Scene scene_;
  WorldOptions options_;
  double period_s_;
  std::unique_ptr<RigidBodyEngine> engine_;
  std::vector<RigidBodyEngine::Overlap> start_overlaps_;
  std::vector<ObjectState> states_;
  std::vector<std::size_t> accelerated_;  // the bodies that moved in the last step (refresh_states)
  ImpulseLedger ledger_;
  // The same running totals' first moments in time (ObjectImpulse::impulse_moment_Nss), differenced with the same
  // owner/epoch rules as the impulses themselves: when within its window each impulse was rendered.
  ImpulseLedger moment_ledger_;
  FeatureExtractor features_;
  AppliedImpulses applied_;
  std::unique_ptr<PassivityLayer> port_;
  std::unique_ptr<CouplingStrategy> coupling_;
  std::vector<std::unique_ptr<DeformableSurface>> surfaces_;  // per object; nullptr unless deformable
  std::vector<std::uint64_t> surface_changes_;              // per object: its surface's changes() the engine has seen
  Eigen::Vector3d total_static_impulse_Ns_ = Eigen::Vector3d::Zero();
  std::map<CounterOwner, std::vector<Eigen::Vector3d>> applied_by_owner_;  // per object (scene ids and the floor)
  std::uint64_t rejected_entries_ = 0;
  std::uint64_t clipped_reports_ = 0;
  double clipped_impulse_Ns_ = 0.0;
  std::uint64_t foreign_reports_ = 0;
  // This step's pushes on dynamic objects, by endpoint slot, with the layer on: who gets each object's unspent budget.
  struct PortPusher {
    std::size_t id;
    std::size_t slot;
    double weight_Ns;
  };
  std::vector<PortPusher> port_pushers_;
  std::array<double, kMaxEndpoints> returned_J_{};  // per slot: handed back since the world session began, J

  std::vector<Endpoint> endpoints_;   // kMaxEndpoints, allocated once
  std::vector<PlaneFrame> frames_;    // per slot; kMaxEndpoints, allocated once (a frame is ~40 KB)
  std::array<FingerState, kMaxEndpoints> fingers_{};  // each slot's finger, as the coupling takes them
  std::size_t slots_used_ = 0;
  std::uint64_t simulated_object_steps_ = 0;
  double floor_penetration_max_m_ = 0.0;
  double time_s_ = 0.0;
  double stalled_s_ = 0.0;  // wall time not simulated so far (note_skipped_steps)
  std::uint64_t steps_taken_ = 0;
};

}  // namespace impetus
