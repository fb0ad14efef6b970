#pragma once
// The virtual world of the world manager: a Scene simulated by ODE, stepped once per world period T_w
// (DESIGN.md §1 "One world step").
//
// Threading and ownership: a World owns its ODE world, space and bodies and is used from one thread. The process must
// have called init_ode_once() (world_manager/ode_runtime.h) before constructing one. Each World saves and restores
// ODE's global random state around its own steps, so runs are bitwise reproducible per World even when several Worlds
// live in one process (tests).
//
// Units SI, world frame right-handed with z up; object ids are scene indices, the floor is scene.floor_object_id().

#include "common/contract/frames.h"
#include "world_manager/scene.h"
#include "world_manager/feature_extractor.h"
#include "world_manager/impulse_ledger.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <cstdint>
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
};

class World {
 public:
  // Validates the options (throws std::invalid_argument), builds the ODE world and seeds ODE's generator with
  // scene.physics.seed. Keeps its own copy of the scene.
  World(const Scene& scene, const WorldOptions& options);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // One world step (DESIGN.md §1): read `report` (nullptr: none yet; the daemon has validated it), apply its impulses
  // (impulse/local coupling) or the finger's penalty force (position coupling), advance ODE by T_w in `substeps`
  // steps, extract the planes around the finger and return the frame. The reference stays valid until the
  // next step.
  const PlaneFrame& step(const HapticReport* report);

  const Scene& scene() const { return scene_; }
  Coupling coupling() const { return options_.coupling; }
  double world_period_s() const { return period_s_; }
  double time_s() const { return time_s_; }
  std::uint64_t steps_taken() const { return steps_taken_; }
  const PlaneFrame& frame() const { return frame_; }

  // State of every scene object after the last step (static ones never change).
  std::span<const ObjectState> states() const { return states_; }
  // Impulse the world applied to object `id` in the last step, and since the start (N·s, N·m·s). In position coupling
  // this is the penalty force times the period.
  const Eigen::Vector3d& step_impulse_Ns(std::size_t id) const { return step_impulse_Ns_[id]; }
  const Eigen::Vector3d& total_impulse_Ns(std::size_t id) const { return total_impulse_Ns_[id]; }
  const Eigen::Vector3d& total_angular_impulse_Nms(std::size_t id) const { return total_angular_impulse_Nms_[id]; }
  // Position coupling: the penalty force held on object `id` during the last step (N).
  const Eigen::Vector3d& coupling_force_N(std::size_t id) const { return coupling_force_N_[id]; }
  // Reaction into static geometry reported by the haptic side (cumulative over all its sessions), N·s.
  const Eigen::Vector3d& total_static_impulse_Ns() const { return total_static_impulse_Ns_; }
  // Report entries ignored because their object id was out of range or their numbers not finite.
  std::uint64_t rejected_entries() const { return rejected_entries_; }

  // Kinetic + gravitational potential energy of the dynamic objects (J), potential measured from the origin.
  double mechanical_energy_J() const;

 private:
  struct OdeHandles;

  void apply_report_impulses(const HapticReport& report);
  void schedule_local_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment,
                              double window_start_s, double window_s);
  void apply_local_schedule(int slot);
  void attach_local_contacts();
  void apply_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                             const Eigen::Vector3d& angular_impulse_Nms);
  void compute_position_coupling();
  void advance_ode();
  void refresh_states();
  void publish(const HapticReport* report);

  Scene scene_;
  WorldOptions options_;
  double period_s_;
  double stiffness_Npm_;
  double damping_Nspm_;
  std::unique_ptr<OdeHandles> ode_;
  unsigned long random_state_;  // ODE's generator state between this World's steps

  std::vector<ObjectState> states_;
  std::vector<Eigen::Matrix3d> inverse_inertia_body_;  // per object; zero for static ones
  ImpulseLedger ledger_;
  // Local coupling: the same running totals' first moments in time (ObjectImpulse::impulse_moment_Nss),
  // differenced with the same session/epoch rules as the impulses themselves.
  ImpulseLedger moment_ledger_;
  // When the impulses of the current step were rendered: the haptic time of the previous report applied.
  std::uint64_t last_report_session_ = 0;
  double last_report_time_s_ = 0.0;
  // Per object, the impulse and angular impulse to apply in each ODE substep of this step (slot `substeps` = after
  // the last substep: a pure velocity change). Zero outside local coupling.
  std::vector<std::vector<Eigen::Vector3d>> local_impulse_schedule_Ns_;
  std::vector<std::vector<Eigen::Vector3d>> local_angular_schedule_Nms_;
  FeatureExtractor features_;
  std::vector<Eigen::Vector3d> step_impulse_Ns_;
  std::vector<Eigen::Vector3d> total_impulse_Ns_;
  std::vector<Eigen::Vector3d> total_angular_impulse_Nms_;
  std::vector<Eigen::Vector3d> coupling_force_N_;
  std::vector<Eigen::Vector3d> coupling_point_m_;
  Eigen::Vector3d total_static_impulse_Ns_ = Eigen::Vector3d::Zero();
  std::uint64_t rejected_entries_ = 0;

  ReachQuery finger_;       // the sampled finger: position coupling's penetration
  ReachQuery plane_query_;  // where planes are extracted: the proxy, reach widened to cover the finger
  bool finger_valid_ = false;
  double time_s_ = 0.0;
  std::uint64_t steps_taken_ = 0;
  PlaneFrame frame_{};
};

}  // namespace impetus
