// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 1 kHz haptic servo (docs/architecture.md §1.2): `tick(finger sample, dt) -> force`, device-agnostic. Composes
// plane interpolation (§3.2), the god-object with friction (§3.3, §6.2), force rendering (§3.3) and impulse integration
// (§3.4). The haptic node wires it to its clock, the world link and a HapticDevice; tests drive it directly.
//
// Threading: one servo thread owns the object; on_plane_frame, tick and report are called from that thread only.
// Real time: the constructor preallocates everything; on_plane_frame and tick never allocate, lock, block or throw.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/device/haptic_device.h"
#include "haptic_controller/force_renderer.h"
#include "haptic_controller/god_object.h"
#include "haptic_controller/hand_port.h"
#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/local_dynamics.h"
#include "haptic_controller/local_yield.h"
#include "haptic_controller/mesh_walk.h"
#include "haptic_controller/plane_motion.h"

#include <array>
#include <cstdint>
#include <limits>
#include <span>

namespace impetus {

struct ServoOptions {
  // Spring k_p and damper k_d of §3.3. NaN: take the scene's value from the world frame. If the world sends no
  // positive value either, stiffness falls back to kFallbackStiffness_Npm and damping to the passivity default
  // passivity_damping_Nspm(k, tick_period_s) (force_renderer.h).
  double stiffness_Npm = std::numeric_limits<double>::quiet_NaN();
  double damping_Nspm = std::numeric_limits<double>::quiet_NaN();
  double tick_period_s = 1e-3;  // nominal servo period T, for the default damping only; forces use the real dt
  double max_force_N = 10.0;    // the device's limit (DeviceLimits): forces are clamped to it
};

// The default for --stiffness when nothing else is given (paper §4.2.1, docs/architecture.md §4).
inline constexpr double kFallbackStiffness_Npm = 2000.0;

struct TickResult {
  Vec3 finger_m{};  // C_j (last valid position when no device)
  Vec3 proxy_m{};   // D_j
  Vec3 force_N{};   // on the finger, after clamping (zero on fault, without device, or out of contact)
  bool render = false;        // command force_N; false: the device's minimum output (no finger, or a fault)
  bool finger_valid = false;  // the device gave a valid finger sample this tick
  bool fault = false;         // non-finite finger or force this tick: force zeroed
  bool world_stale = false;   // the newest world frame is stale (common/runtime/staleness.h): its planes hold
  bool sticking = false;      // friction holds the proxy
  double stiffness_Npm = 0.0;  // k_p and k_d this tick (flags, else the world's, else the fallbacks above)
  double damping_Nspm = 0.0;
  int active_planes = 0;      // constraints holding the proxy (0 free, 1 face, 2 edge, 3 corner; 4 infeasible pinch)
  double interpolation_weight = 1.0;  // w of §3.2
};

struct ServoCounters {
  std::uint64_t ticks = 0;
  std::uint64_t faults = 0;            // non-finite finger position or force
  std::uint64_t force_clamps = 0;      // |f| limited to max_force_N
  std::uint64_t infeasible_contacts = 0;  // pinch: no point outside all planes
  std::uint64_t stale_world_ticks = 0;
  std::uint64_t no_device_ticks = 0;
  std::uint64_t servo_stalls = 0;      // ticks that came longer than kCommandStale_s after the last (a stalled servo)
  std::uint64_t dropped_impulse_shares = 0;  // reaction shares that found no report entry
  // Frame-boundary continuity, any coupling. At the first tick after a world frame, for every plane that
  // held the proxy in the tick before: the second difference of the plane's signed distance at that proxy over the
  // three ticks around the boundary, |d_j − 2·d_{j−1} + d_{j−2}|. Steady plane motion cancels; what remains is the
  // jump (or the velocity kink × Δt) the finger feels when the new frame takes over, plus the plane's own
  // acceleration × Δt² (≈ 0.02 mm for 20 N on 1 kg).
  std::uint64_t contact_frame_boundaries = 0;  // boundaries measured (planes in contact across them)
  double frame_jump_max_m = 0.0;
  // Local coupling: the largest disagreement, at the proxy, between the plane the finger was feeling and the world's
  // new plane of a touched object when a frame arrived (before the blend hides it; local_dynamics.h).
  double local_model_error_max_m = 0.0;
  // Local coupling over a delayed link (local_dynamics.h, "Delay"): the most ticks one frame's replay caught up on
  // (the link's round trip plus the world's step, as the servo saw it), frames whose missing ticks the model's log no
  // longer held, and shares the log had no room for.
  std::uint64_t local_replayed_ticks_max = 0;
  std::uint64_t local_replay_gaps = 0;
  std::uint64_t local_unlogged_shares = 0;
};

class HapticServo {
 public:
  // Serves endpoint `endpoint` of `haptic_session` (its reports name them).
  HapticServo(const ServoOptions& options, std::uint64_t haptic_session, EndpointId endpoint = 0);

  // A validated world frame arrived at servo time now_s. Frames of a new world session restart interpolation.
  void on_plane_frame(const PlaneFrame& frame, double now_s);

  // One tick at servo time now_s, dt_s after the previous tick (real elapsed time). finger == nullptr means no
  // device is attached or its reading is stale: no finger, minimum output, no contact, nothing accumulated; an
  // invalid sample is the same plus a counted fault.
  const TickResult& tick(const FingerSample* finger, double now_s, double dt_s);

  // Another endpoint of the same controller pushed these shares in this tick (its accumulator().last_shares()):
  // local coupling's model moves the objects by them too, so each finger feels the others' pushes at once (paper
  // §6.3; without it a grasped object gives way to each finger as if the other were not there). Other couplings
  // ignore them: their planes move only with the world's frames. Call after this tick's tick().
  void take_other_shares(const ImpulseShare* shares, int count) {
    if (have_frame_) motion_->take_shares(shares, count);
  }
  // What the last tick gave (as tick() returned it).
  const TickResult& last_result() const { return result_; }
  // A world frame has arrived since the servo started (a world it renders, even if stale now).
  bool has_world() const { return have_frame_; }
  // Cumulative impulses and the finger, updated by every tick; the caller seals and publishes it.
  const HapticReport& report() const { return accumulator_.report(); }
  const ServoCounters& counters() const { return counters_; }
  const ImpulseAccumulator& accumulator() const { return accumulator_; }
  const PlaneSet& planes() const { return planes_; }  // the interpolated planes of the last tick
  const LocalDynamics& local_dynamics() const { return local_; }  // local coupling's model (tests)
  const HandPort& hand_port() const { return hand_port_; }  // the passivity layer's half at the hand

 private:
  void idle_tick(bool fault);
  void measure_frame_boundary(const ProxySolution& contact);

  // A plane that held the proxy in the last tick, with its value one tick before (frame-boundary diagnostic).
  struct WatchedPlane {
    std::int32_t object_id = -1;
    int occurrence = 0;
    Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    bool has_previous = false;
    Eigen::Vector3d previous_point_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d previous_normal = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();
  };

  ServoOptions options_;
  PlaneFrame current_frame_{};
  bool have_frame_ = false;
  double frame_arrival_s_ = 0.0;
  PlaneSet planes_{};
  MeshHold mesh_hold_{};  // the triangles the meshes' walk held last tick (mesh_walk.h)
  GodObject god_object_;
  ForceRenderer renderer_;
  ImpulseAccumulator accumulator_;
  InterpolatedPlanes interpolated_;
  LocalDynamics local_;
  LocalYield local_yield_;  // deformable surfaces between frames
  HandPort hand_port_;
  PlaneMotion* motion_ = &interpolated_;  // the coupling's, chosen by each frame
  bool frame_since_last_tick_ = false;
  std::array<WatchedPlane, kMaxActiveConstraints + 1> watched_{};
  int watched_count_ = 0;
  Eigen::Vector3d finger_m_ = Eigen::Vector3d::Zero();
  bool finger_known_ = false;
  TickResult result_{};
  ServoCounters counters_{};
};

// After every servo of one controller has ticked: hands each servo the others' shares of this tick
// (HapticServo::take_other_shares), in order. Allocation-free.
void exchange_pushes(std::span<HapticServo* const> servos);

}  // namespace impetus
