// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/servo.h"

#include "common/runtime/staleness.h"
#include "haptic_controller/local_yield.h"
#include "haptic_controller/plane_interpolator.h"
#include "haptic_controller/plane_matching.h"
#include "haptic_controller/shape_planes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

double positive_or(double value, double fallback) { return value > 0.0 && std::isfinite(value) ? value : fallback; }

double signed_distance_m(const Eigen::Vector3d& x_m, const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal) {
  return normal.dot(x_m - point_m);
}

}  // namespace

HapticServo::HapticServo(const ServoOptions& options, std::uint64_t haptic_session, EndpointId endpoint)
    : options_(options), renderer_(options.max_force_N), accumulator_(haptic_session, endpoint), local_(haptic_session) {}

void HapticServo::on_plane_frame(const PlaneFrame& frame, double now_s) {
  // Interpolate from the previous frame of the same world session only; the first frame starts where it is.
  const bool continues = have_frame_ && frame.world_session == current_frame_.world_session;
  // The one place the coupling is read: local coupling's planes move with a local model (paper §6.3), the others'
  // are interpolated (§3.2).
  motion_ = frame.coupling == Coupling::local ? static_cast<PlaneMotion*>(&local_) : &interpolated_;
  motion_->on_frame(continues ? current_frame_ : frame, frame, continues ? &planes_ : nullptr,
                    to_eigen(result_.proxy_m));
  if (continues) {
    counters_.local_model_error_max_m = std::max(counters_.local_model_error_max_m, motion_->frame_disagreement_m());
  }
  if (motion_ == &local_) {
    counters_.local_replayed_ticks_max = std::max(counters_.local_replayed_ticks_max, local_.last_replayed_ticks());
    counters_.local_replay_gaps = local_.replay_gaps();
    counters_.local_unlogged_shares = local_.unlogged_shares();
  }
  if (!continues) local_yield_.clear();  // a new world: its first frame shows none of our pushes
  frame_since_last_tick_ = true;
  copy_used(frame, current_frame_);
  have_frame_ = true;
  frame_arrival_s_ = now_s;
  accumulator_.on_plane_frame(frame);
  hand_port_.on_plane_frame(frame);
  // The link's round trip as seen here (HapticReport::link_round_trip_s): the ticks from the report this frame
  // applied to now. 0 when it applied the tick just rendered.
  HapticReport& report = accumulator_.report();
  if (frame.report_session_applied == report.haptic_session && frame.report_tick_applied > 0 &&
      counters_.ticks >= frame.report_tick_applied) {
    const auto round_trip_ticks = static_cast<double>(counters_.ticks - frame.report_tick_applied);
    report.link_round_trip_s = round_trip_ticks * options_.tick_period_s;
  }
}

void HapticServo::measure_frame_boundary(const ProxySolution& contact) {
  // ServoCounters::frame_jump_max_m: second difference across the boundary at the proxy of the tick before.
  if (frame_since_last_tick_) {
    bool measured = false;
    for (int k = 0; k < watched_count_; ++k) {
      const WatchedPlane& seen = watched_[static_cast<std::size_t>(k)];
      const int now = find_plane(planes_, seen.object_id, seen.occurrence);
      if (!seen.has_previous || now < 0) continue;
      const ContactPlane& plane = planes_.planes[static_cast<std::size_t>(now)];
      const double d_now = signed_distance_m(seen.proxy_m, plane.point_m, plane.normal);
      const double d_last = signed_distance_m(seen.proxy_m, seen.point_m, seen.normal);
      const double d_before = signed_distance_m(seen.proxy_m, seen.previous_point_m, seen.previous_normal);
      counters_.frame_jump_max_m = std::max(counters_.frame_jump_max_m, std::fabs(d_now - 2.0 * d_last + d_before));
      measured = true;
    }
    if (measured) ++counters_.contact_frame_boundaries;
  }
  frame_since_last_tick_ = false;

  std::array<WatchedPlane, kMaxActiveConstraints + 1> next{};
  int next_count = 0;
  for (int j = 0; j < contact.active_count && j < static_cast<int>(next.size()); ++j) {
    const auto index = static_cast<std::uint32_t>(contact.active[j].plane);
    const ContactPlane& plane = planes_.planes[index];
    WatchedPlane& entry = next[static_cast<std::size_t>(next_count++)];
    entry.object_id = plane.object_id;
    entry.occurrence = occurrence_of(planes_, index);
    entry.point_m = plane.point_m;
    entry.normal = plane.normal;
    entry.proxy_m = contact.proxy_m;
    for (int k = 0; k < watched_count_; ++k) {
      const WatchedPlane& seen = watched_[static_cast<std::size_t>(k)];
      if (seen.object_id == entry.object_id && seen.occurrence == entry.occurrence) {
        entry.has_previous = true;
        entry.previous_point_m = seen.point_m;
        entry.previous_normal = seen.normal;
      }
    }
  }
  watched_ = next;
  watched_count_ = next_count;
}

void HapticServo::idle_tick(bool fault) {
  watched_count_ = 0;
  hand_port_.idle();
  renderer_.reset();
  result_.force_N = {};
  accumulator_.report().force_N = {};
  result_.render = false;
  result_.fault = fault;
  result_.sticking = false;
  result_.active_planes = 0;
  result_.proxy_m = result_.finger_m;
}

const TickResult& HapticServo::tick(const FingerSample* finger, double now_s, double dt_s) {
  ++counters_.ticks;
  HapticReport& report = accumulator_.report();
  report.tick = counters_.ticks;
  report.haptic_time_s = now_s;
  local_.note_tick(counters_.ticks);

  // 1. Finger position C_j.
  const bool finger_valid = finger != nullptr && finger->valid && finger->position_m.allFinite();
  result_.finger_valid = finger_valid;
  if (!finger_valid) {
    if (finger) ++counters_.faults;
    else ++counters_.no_device_ticks;
    report.finger_valid = 0;
    report.finger_velocity_mps = {};
    if (finger_known_) god_object_.end_finger_session();  // what it pressed, to resume the press if it comes back
    finger_known_ = false;
    idle_tick(finger != nullptr);
    return result_;
  }
  // A servo that did not run for longer than the device's command watchdog (common/runtime/staleness.h) finds the
  // device at minimum output and the hand where it went meanwhile, possibly deep in an object: a new finger session,
  // so the finger is not kicked out (god_object.h), and the hold of this tick's command is the watchdog's at most.
  if (finger_known_ && command_stale(dt_s)) {
    ++counters_.servo_stalls;
    god_object_.end_finger_session();
    finger_known_ = false;
  }
  const double hold_s = std::min(dt_s, kCommandStale_s);
  const Eigen::Vector3d finger_m = finger->position_m;
  const bool paired_finger = finger_known_ && dt_s > 0.0 && std::isfinite(dt_s);  // a displacement since the last tick
  const Eigen::Vector3d finger_velocity_mps =
      paired_finger ? Eigen::Vector3d((finger_m - finger_m_) / dt_s) : Eigen::Vector3d::Zero();
  if (!finger_known_) god_object_.begin_finger_session(finger_m);  // a finger that appears inside an object is not kicked
  finger_m_ = finger_m;
  finger_known_ = true;
  result_.finger_m = to_vec3(finger_m);
  report.finger_m = result_.finger_m;
  report.proxy_m = result_.finger_m;  // until the proxy of this tick is known
  report.finger_velocity_mps = to_vec3(finger_velocity_mps);
  report.finger_valid = 1;

  // 2. Planes interpolated between world frames i−1 and i (§3.2); a stale world keeps its last planes (w = 1).
  double w = 1.0;
  result_.world_stale = false;
  if (have_frame_) {
    w = interpolation_weight(now_s, frame_arrival_s_, current_frame_.world_period_s);
    result_.world_stale = world_stale(now_s - frame_arrival_s_, current_frame_.world_period_s);
    if (result_.world_stale) ++counters_.stale_world_ticks;
    motion_->planes_for_tick(w, dt_s, result_.world_stale, to_eigen(result_.proxy_m), planes_);
  } else {
    planes_.count = 0;
  }
  result_.interpolation_weight = w;

  // Planes that carry their shape taken again at the last proxy, or at the finger past a body the way to it does not
  // enter (shape_planes.h).
  retake_shape_planes(planes_, to_eigen(result_.proxy_m), finger_m, &mesh_hold_);
  // Deformable surfaces yield by the push beyond yield the world has not yet dented them by, elastic ones by this
  // tick's push (local_yield.h).
  const double stiffness_Npm =
      std::isnan(options_.stiffness_Npm) ? positive_or(current_frame_.stiffness_Npm, kFallbackStiffness_Npm)
                                         : options_.stiffness_Npm;
  if (have_frame_) {
    local_yield_.apply(current_frame_, report.haptic_session, to_eigen(result_.proxy_m), finger_m, stiffness_Npm,
                       planes_);
  }

  // 3. Proxy D_j (god-object with friction).
  planes_.valid_within_m =
      current_frame_.reach_radius_m > 0.0 ? current_frame_.reach_radius_m : std::numeric_limits<double>::infinity();
  const GodObjectResult& contact =
      god_object_.solve(planes_, finger_m, dt_s, &mesh_hold_);
  if (!contact.contact.proxy_m.allFinite()) {  // only a non-finite plane could do this; frames are validated upstream
    ++counters_.faults;
    god_object_.reset();
    idle_tick(true);
    return result_;
  }
  result_.proxy_m = to_vec3(contact.contact.proxy_m);
  report.proxy_m = result_.proxy_m;
  measure_frame_boundary(contact.contact);
  result_.active_planes = contact.contact.active_count;
  result_.sticking = contact.sticking;
  if (contact.contact.infeasible) ++counters_.infeasible_contacts;

  // 4. Force f_j on the finger (§3.3). Out of contact nothing is touched, so nothing pushes: the damper acts only
  //    while a plane holds the proxy (its history still advances, so the first contact tick is continuous).
  const double damping_Nspm =
      std::isnan(options_.damping_Nspm)
          ? positive_or(current_frame_.damping_Nspm, passivity_damping_Nspm(stiffness_Npm, options_.tick_period_s))
          : options_.damping_Nspm;
  result_.stiffness_Npm = stiffness_Npm;
  result_.damping_Nspm = damping_Nspm;
  const RenderedForce rendered =
      renderer_.render(contact.contact.proxy_m, finger_m, stiffness_Npm, damping_Nspm, dt_s);
  Eigen::Vector3d force_N = contact.contact.active_count > 0 ? rendered.force_N : Eigen::Vector3d::Zero();
  if (have_frame_ && contact.contact.active_count > 0) {
    // Planes that give way within the tick (local coupling) solve it implicitly (local_dynamics.h yield_scale).
    force_N *= motion_->yield_scale(planes_, contact.contact, force_N, stiffness_Npm, damping_Nspm, dt_s);
  }
  result_.fault = rendered.fault;
  if (rendered.fault) ++counters_.faults;
  if (rendered.clamped && contact.contact.active_count > 0) ++counters_.force_clamps;
  result_.force_N = to_vec3(force_N);
  report.force_N = result_.force_N;

  // 5. The reaction −f_j·Δt, shared among the touched objects (§3.4).
  accumulator_.add(planes_, contact.contact, force_N, hold_s > 0.0 && std::isfinite(hold_s) ? hold_s : 0.0,
                   counters_.ticks);
  counters_.dropped_impulse_shares = accumulator_.dropped_shares();
  local_yield_.record(counters_.ticks, contact.contact.proxy_m, accumulator_.last_shares(),
                      accumulator_.last_share_count());
  // The objects give way at the haptic rate (local coupling, paper §6.3): this tick's shares move the model.
  if (have_frame_) motion_->take_shares(accumulator_.last_shares(), accumulator_.last_share_count());

  // 5b. With the passivity layer on, the finger gets no more energy than it put in and the world handed back, and
  //     the world gets what the proxy's spring would not give back (hand_port.h); the objects keep the reaction of
  //     the contact force.
  if (hand_port_.active()) {
    const double stored_J = contact.contact.active_count > 0
                                ? 0.5 * stiffness_Npm * (contact.contact.proxy_m - finger_m).squaredNorm()
                                : 0.0;
    const Eigen::Vector3d displacement_m = finger_velocity_mps * dt_s;
    const HandPortTick port = hand_port_.tick(force_N, paired_finger ? &displacement_m : nullptr,
                                              accumulator_.pushed_dynamic(), stored_J);
    hand_port_.credit(accumulator_.set_last_credit(port.credit_J));
    result_.force_N = to_vec3(port.force_N);
    report.force_N = result_.force_N;
  } else {
    hand_port_.idle();
  }

  // 6. The device renders it (docs/architecture.md §1.2 step 6: the haptic node commands the device).
  result_.render = true;
  return result_;
}

void exchange_pushes(std::span<HapticServo* const> servos) {
  if (servos.size() < 2) return;
  for (HapticServo* receiver : servos) {
    for (const HapticServo* pusher : servos) {
      if (pusher == receiver) continue;
      receiver->take_other_shares(pusher->accumulator().last_shares(), pusher->accumulator().last_share_count());
    }
  }
}

}  // namespace impetus
