// SPDX-License-Identifier: Apache-2.0
#include "loop/simulation.h"

#include "loop/in_process_rig.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace impetus {
namespace {

std::string point_text(const Vec3& v) {
  char text[96];
  std::snprintf(text, sizeof text, "(%g, %g, %g)", v[0], v[1], v[2]);
  return text;
}

// The trial options a closed loop accepts: no scripted motion and no end of its own.
void check_closed_loop(const InProcessTrialOptions& trial) {
  if (!trial.trajectory.empty() || !trial.fingers.empty() || !trial.finger_paths.empty()) {
    throw std::invalid_argument("a closed loop moves its fingers itself: give their names and start points, no "
                                "trajectory");
  }
  if (!trial.followers.empty()) throw std::invalid_argument("a closed loop has one user: no followers");
  if (trial.duration_s != 0.0) throw std::invalid_argument("a closed loop ends when finish() is called: no duration_s");
}

// Each finger starts at rest at its start point: a one-point trajectory, which the device checks is inside its frame.
std::vector<NamedFinger> starting_fingers(const std::vector<SimulationFinger>& fingers) {
  std::vector<NamedFinger> out;
  for (const SimulationFinger& finger : fingers) {
    if (!all_finite(finger.start_m)) {
      throw std::invalid_argument("finger '" + finger.name + "': start_m must be finite, not " +
                                  point_text(finger.start_m));
    }
    Trajectory start = Trajectory::from_waypoints({{0.0, finger.start_m}}, "finger '" + finger.name + "' start");
    out.push_back({finger.name, std::move(start)});
  }
  check_fingers(out, kMaxFingers);
  return out;
}

}  // namespace

Simulation::Simulation(const SimulationOptions& options) {
  check_closed_loop(options.trial);
  std::vector<NamedFinger> fingers = starting_fingers(options.fingers);
  finger_count_ = fingers.size();
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  rig_ = std::make_unique<InProcessRig>(options.trial, std::move(fingers));
  // Steered from the start: the target holds at the start point until the caller moves it (a one-point trajectory
  // would otherwise end the device's session at once).
  for (std::size_t k = 0; k < finger_count_; ++k) rig_->fingers().sim(k).steer(options.fingers[k].start_m);
  for (const SceneObject& object : rig_->world().world().scene().objects) object_names_.push_back(object.name);
}

Simulation::~Simulation() {
  try {
    finish();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "impetus: the closed loop did not finish cleanly: %s\n", error.what());
  }
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  rig_.reset();
}

double Simulation::tick_period_s() const { return rig_->tick_period_s(); }

std::vector<std::string> Simulation::warnings() const { return rig_->world().warnings(); }

double Simulation::device_time_s() const { return rig_->fingers().sim(0).time_s(); }

void Simulation::check_finger(std::size_t finger) const {
  if (finger >= finger_count_) {
    throw std::invalid_argument("finger: " + std::to_string(finger) + " is not one of the " +
                                std::to_string(finger_count_) + " fingers");
  }
}

void Simulation::set_target(std::size_t finger, const Vec3& target_m) {
  check_finger(finger);
  if (!all_finite(target_m)) throw std::invalid_argument("target_m: must be finite, not " + point_text(target_m));
  rig_->fingers().sim(finger).steer(target_m);
}

void Simulation::set_hand_force(std::size_t finger, const Vec3& force_N) {
  check_finger(finger);
  if (!all_finite(force_N)) throw std::invalid_argument("force_N: must be finite, not " + point_text(force_N));
  rig_->fingers().sim(finger).set_hand_force(force_N);
}

std::uint64_t Simulation::step(std::uint64_t count, std::span<const Vec3> targets, std::span<FingerTick> out) {
  if (finished_) throw std::logic_error("the simulation has finished: no more ticks");
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("ticks: at most " + std::to_string(std::numeric_limits<std::uint32_t>::max()) +
                                " in one call, not " + std::to_string(count));
  }
  const std::size_t expected = static_cast<std::size_t>(count) * finger_count_;
  if (!targets.empty() && targets.size() != expected) {
    throw std::invalid_argument("targets: " + std::to_string(count) + " ticks of " + std::to_string(finger_count_) +
                                " fingers need " + std::to_string(expected) + " points, not " +
                                std::to_string(targets.size()));
  }
  if (!out.empty() && out.size() != expected) {
    throw std::invalid_argument("out: needs room for " + std::to_string(expected) + " records, not " +
                                std::to_string(out.size()));
  }
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (!all_finite(targets[i])) {
      throw std::invalid_argument("targets: tick " + std::to_string(i / finger_count_) + ", finger " +
                                  std::to_string(i % finger_count_) + ": " + point_text(targets[i]) +
                                  " is not finite");
    }
  }
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  HapticNode& haptic = rig_->haptic();
  SimulatedFingers& fingers = rig_->fingers();
  std::uint64_t done = 0;
  for (; done < count; ++done) {
    if (!targets.empty()) {
      for (std::size_t k = 0; k < finger_count_; ++k) fingers.sim(k).steer(targets[done * finger_count_ + k]);
    }
    // False only for a stop request: a steered device never leaves and a closed loop has no duration.
    if (!haptic.lockstep_tick(ticks_)) break;
    const double time_s = static_cast<double>(ticks_) * tick_period_s();
    ++ticks_;
    if (out.empty()) continue;
    for (std::size_t k = 0; k < finger_count_; ++k) {
      const HapticServo& servo = haptic.servo(static_cast<EndpointId>(k));
      const TickResult& result = servo.last_result();
      FingerTick& record = out[done * finger_count_ + k];
      record.time_s = time_s;
      record.target_m = fingers.sim(k).target_m();
      record.finger_m = result.finger_m;
      record.finger_velocity_mps = fingers.sim(k).finger_velocity_mps();
      record.proxy_m = result.proxy_m;
      record.force_N = result.force_N;
      record.object_impulse_Ns = object_impulse_total_Ns(servo.report());
      record.active_planes = result.active_planes;
    }
  }
  return done;
}

std::vector<SimulationObject> Simulation::objects() const {
  const World& world = rig_->world().world();
  const std::span<const ObjectState> states = world.states();
  std::vector<SimulationObject> out(states.size());
  for (std::size_t id = 0; id < states.size(); ++id) {
    const ObjectState& state = states[id];
    SimulationObject& object = out[id];
    object.position_m = to_vec3(state.pose.position_m);
    object.orientation_wxyz = {state.pose.orientation.w(), state.pose.orientation.x(), state.pose.orientation.y(),
                               state.pose.orientation.z()};
    object.velocity_mps = to_vec3(state.velocity_mps);
    object.angular_velocity_radps = to_vec3(state.angular_velocity_radps);
    object.impulse_Ns = to_vec3(world.total_impulse_Ns(id));
  }
  return out;
}

const nlohmann::json& Simulation::finish() {
  if (finished_) return summary_;
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  finished_ = true;
  rig_->finish();
  summary_ = rig_->summary();
  return summary_;
}

}  // namespace impetus
