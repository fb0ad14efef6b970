#include "haptic_controller/servo.h"

#include "haptic_controller/plane_interpolator.h"
#include "haptic_controller/tension_distribution.h"

#include <cmath>

namespace impetus {
namespace {

double positive_or(double value, double fallback) { return value > 0.0 && std::isfinite(value) ? value : fallback; }

}  // namespace

HapticServo::HapticServo(const ServoOptions& options, std::uint64_t haptic_session)
    : options_(options),
      kinematics_(options.geometry),
      renderer_(options.geometry.max_force_N),
      accumulator_(haptic_session) {
  for (int i = 0; i < kStringCount; ++i) motors_m_[i] = kinematics_.motor_m(i);
  result_.tension_N.fill(options_.geometry.tension_min_N);
}

void HapticServo::on_plane_frame(const PlaneFrame& frame, double now_s) {
  // Interpolate from the previous frame of the same world session only; the first frame starts where it is.
  const bool continues = have_frame_ && frame.world_session == current_frame_.world_session;
  previous_frame_ = continues ? current_frame_ : frame;
  current_frame_ = frame;
  have_frame_ = true;
  frame_arrival_s_ = now_s;
  accumulator_.on_plane_frame(frame);
}

void HapticServo::idle_tick(bool fault) {
  god_object_.reset();
  renderer_.reset();
  result_.force_N = {};
  result_.tension_N.fill(options_.geometry.tension_min_N);
  result_.saturated = false;
  result_.fault = fault;
  result_.sticking = false;
  result_.active_planes = 0;
  result_.proxy_m = result_.finger_m;
}

const TickResult& HapticServo::tick(const DeviceState* device, double now_s, double dt_s) {
  ++counters_.ticks;
  HapticReport& report = accumulator_.report();
  report.tick = counters_.ticks;
  report.haptic_time_s = now_s;

  // 1. Finger position C_j.
  Eigen::Vector3d finger_m = finger_m_;
  const bool finger_valid = device != nullptr && kinematics_.finger_position(device->encoder_counts, finger_m);
  result_.finger_valid = finger_valid;
  if (!finger_valid) {
    if (device) ++counters_.faults;
    else ++counters_.no_device_ticks;
    report.finger_valid = 0;
    report.finger_velocity_mps = {};
    finger_known_ = false;
    idle_tick(device != nullptr);
    return result_;
  }
  const Eigen::Vector3d finger_velocity_mps =
      finger_known_ && dt_s > 0.0 ? Eigen::Vector3d((finger_m - finger_m_) / dt_s) : Eigen::Vector3d::Zero();
  if (!finger_known_) god_object_.begin_finger_session();  // a finger that appears inside an object is not kicked
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
    result_.world_stale = now_s - frame_arrival_s_ > kStaleWorldPeriods * current_frame_.world_period_s;
    if (result_.world_stale) ++counters_.stale_world_ticks;
    interpolate_planes(previous_frame_, current_frame_, w, planes_);
  } else {
    planes_.count = 0;
  }
  result_.interpolation_weight = w;

  // 3. Proxy D_j (god-object with friction).
  const GodObjectResult& contact = god_object_.solve(planes_, finger_m, dt_s);
  if (!contact.contact.proxy_m.allFinite()) {  // only a non-finite plane could do this; frames are validated upstream
    ++counters_.faults;
    idle_tick(true);
    return result_;
  }
  result_.proxy_m = to_vec3(contact.contact.proxy_m);
  report.proxy_m = result_.proxy_m;
  result_.active_planes = contact.contact.active_count;
  result_.sticking = contact.sticking;
  if (contact.contact.infeasible) ++counters_.infeasible_contacts;

  // 4. Force f_j on the finger (§3.3). Out of contact nothing is touched, so nothing pushes: the damper acts only
  //    while a plane holds the proxy (its history still advances, so the first contact tick is continuous).
  const double stiffness_Npm =
      std::isnan(options_.stiffness_Npm) ? positive_or(current_frame_.stiffness_Npm, kFallbackStiffness_Npm)
                                         : options_.stiffness_Npm;
  const double damping_Nspm =
      std::isnan(options_.damping_Nspm)
          ? positive_or(current_frame_.damping_Nspm, passivity_damping_Nspm(stiffness_Npm, options_.tick_period_s))
          : options_.damping_Nspm;
  const RenderedForce rendered =
      renderer_.render(contact.contact.proxy_m, finger_m, stiffness_Npm, damping_Nspm, dt_s);
  Eigen::Vector3d force_N = contact.contact.active_count > 0 ? rendered.force_N : Eigen::Vector3d::Zero();
  result_.fault = rendered.fault;
  if (rendered.fault) ++counters_.faults;
  if (rendered.clamped && contact.contact.active_count > 0) ++counters_.force_clamps;
  result_.force_N = to_vec3(force_N);

  // 5. The reaction −f_j·Δt, shared among the touched objects (§3.4).
  accumulator_.add(planes_, contact.contact, force_N, dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 0.0,
                   counters_.ticks);
  counters_.dropped_impulse_shares = accumulator_.dropped_shares();

  // 6. String tensions.
  const TensionSolution tensions = distribute_tension(force_N, finger_m, motors_m_, options_.geometry.tension_min_N,
                                                      options_.geometry.tension_max_N);
  result_.tension_N = tensions.tension_N;
  result_.saturated = tensions.saturated;
  if (tensions.saturated) ++counters_.saturations;
  return result_;
}

}  // namespace impetus
