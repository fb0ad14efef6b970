// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world.h"

#include "world_manager/engine/ode_engine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {

World::World(const Scene& scene, const WorldOptions& options)
    : scene_(scene),
      options_(options),
      period_s_(1.0 / options.world_rate_hz.value_or(scene.physics.world_rate_hz)),
      states_(scene.objects.size()),
      ledger_(scene.objects.size() + 1),
      moment_ledger_(scene.objects.size() + 1),
      features_(scene_),
      applied_(scene.objects.size()) {
  if (options.world_rate_hz && !(*options.world_rate_hz > 0.0 && std::isfinite(*options.world_rate_hz))) {
    throw std::invalid_argument("world rate must be positive and finite, got " +
                                std::to_string(*options.world_rate_hz));
  }
  const double stiffness_Npm = options.position_stiffness_Npm.value_or(scene.haptic.stiffness_Npm);
  const double damping_Nspm = options.position_damping_Nspm.value_or(scene.haptic.damping_Nspm);
  if (!(stiffness_Npm > 0.0) || !std::isfinite(stiffness_Npm)) {
    throw std::invalid_argument("position-coupling stiffness must be positive, got " + std::to_string(stiffness_Npm));
  }
  if (!(damping_Nspm >= 0.0) || !std::isfinite(damping_Nspm)) {
    throw std::invalid_argument("position-coupling damping must be non-negative, got " + std::to_string(damping_Nspm));
  }
  if (options.world_session == 0) throw std::invalid_argument("world_session must be nonzero");

  engine_ = std::make_unique<OdeEngine>(scene_);
  const CouplingContext context{scene_, period_s_, scene_.physics.substeps, *engine_, states_, applied_};
  coupling_ = make_coupling(options.coupling, context, stiffness_Npm, damping_Nspm);

  refresh_states();
  features_.index(states_, period_s_);
  frame_.world_session = options_.world_session;
  frame_.world_period_s = period_s_;
  frame_.coupling = options_.coupling;
  frame_.gravity_mps2 = scene_.gravity_mps2;
  frame_.world_substep_s = period_s_ / scene_.physics.substeps;
  frame_.reach_radius_m = scene_.haptic.reach_radius_m;
}

World::~World() = default;

const PlaneFrame& World::step(const HapticReport* report) {
  // Step 1: the finger, only if a device is attached. Without a new report the last sample stays the latest one.
  if (report != nullptr) {
    finger_.valid = report->finger_valid != 0 && all_finite(report->finger_m) &&
                    all_finite(report->finger_velocity_mps);
    if (finger_.valid) {
      finger_.finger.position_m = to_eigen(report->finger_m);
      finger_.finger.velocity_mps = to_eigen(report->finger_velocity_mps);
      // Planes come from around the proxy (feature_extractor.h, ReachQuery); a report without a finite proxy
      // falls back to the finger.
      plane_query_ = finger_.finger;
      if (all_finite(report->proxy_m)) {
        plane_query_.position_m = to_eigen(report->proxy_m);
        plane_query_.reach_extra_m = (finger_.finger.position_m - plane_query_.position_m).norm();
      }
    }
  }

  // Step 2: the coupling.
  applied_.begin_step();
  // Only totals counted against this world's own frames: a report counted against another world session (a world
  // that died, or none yet) carries impulse this world never showed, and its objects started afresh from the scene.
  const HapticReport* applied_report =
      report != nullptr && report->world_session == options_.world_session ? report : nullptr;
  if (report != nullptr && applied_report == nullptr) ++foreign_reports_;
  if (applied_report != nullptr) take_report(*applied_report);
  coupling_->before_step(finger_, features_);

  // Step 3: the engine, with the coupling's forces before every substep.
  engine_->step(scene_.physics.substeps, period_s_ / scene_.physics.substeps, coupling_->needs_contacts(), *coupling_);
  coupling_->after_step();
  ++steps_taken_;
  time_s_ = static_cast<double>(steps_taken_) * period_s_;  // no drift from summing periods
  refresh_states();

  // Step 4: planes and publication.
  features_.index(states_, period_s_);
  publish(applied_report);
  return frame_;
}

void World::take_report(const HapticReport& report) {
  // The impulses of this report were rendered after the previous report applied and up to this one: that window
  // maps onto this step (local coupling places each impulse in it).
  const bool known_start = last_report_session_ == report.haptic_session && report.haptic_time_s > last_report_time_s_;
  RenderWindow window;
  window.length_s = known_start ? report.haptic_time_s - last_report_time_s_ : period_s_;
  window.start_s = report.haptic_time_s - window.length_s;
  last_report_session_ = report.haptic_session;
  last_report_time_s_ = report.haptic_time_s;
  const std::size_t floor_id = scene_.objects.size();
  const CounterOwner owner{report.haptic_session, report.endpoint};
  const std::uint32_t count = std::min(report.entry_count, kMaxImpulseEntries);
  for (std::uint32_t i = 0; i < count; ++i) {
    const ObjectImpulse& entry = report.entries[i];
    if (entry.object_id < 0 || static_cast<std::size_t>(entry.object_id) > floor_id ||
        !all_finite(entry.impulse_Ns) || !all_finite(entry.angular_impulse_Nms)) {
      ++rejected_entries_;
      continue;
    }
    const auto id = static_cast<std::size_t>(entry.object_id);
    const ImpulseDelta delta = ledger_.take(owner, entry);
    ObjectImpulse moments = entry;  // the moments through the same ledger rules (owner, epoch, baseline)
    moments.impulse_Ns = entry.impulse_moment_Nss;
    moments.angular_impulse_Nms = entry.angular_impulse_moment_Nmss;
    const ImpulseDelta moment = moment_ledger_.take(owner, moments);
    if (id < floor_id && scene_.objects[id].dynamic) {
      const bool moment_finite = all_finite(entry.impulse_moment_Nss) && all_finite(entry.angular_impulse_moment_Nmss);
      coupling_->take_impulse(id, delta, moment, moment_finite, window);
    } else {
      total_static_impulse_Ns_ += delta.impulse_Ns;  // the haptic side named static geometry: it absorbs the push
    }
  }
  if (all_finite(report.static_impulse_Ns)) {
    total_static_impulse_Ns_ += ledger_.take_static(owner, report.static_impulse_Ns);
  }
}

const std::vector<std::size_t>& World::escaped() const { return engine_->escaped(); }

void World::refresh_states() {
  for (std::size_t id = 0; id < states_.size(); ++id) {
    ObjectState& state = states_[id];
    const SceneObject& object = scene_.objects[id];
    if (!object.dynamic) {
      const auto& q = object.orientation_wxyz;
      state.pose.position_m = to_eigen(object.position_m);
      state.pose.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
      continue;
    }
    engine_->read_state(id, state);
    state.inverse_mass_per_kg = 1.0 / object.mass_kg;
    const Eigen::Matrix3d rotation = state.pose.orientation.toRotationMatrix();
    state.inverse_inertia_world = rotation * engine_->inverse_inertia_body(id) * rotation.transpose();
  }
}

void World::publish(const HapticReport* applied_report) {
  frame_.frame_index = steps_taken_ - 1;
  if (applied_report != nullptr) {
    frame_.report_tick_applied = applied_report->tick;
    frame_.report_session_applied = applied_report->haptic_session;
  }
  frame_.world_time_s = time_s_;
  frame_.stiffness_Npm = scene_.haptic.stiffness_Npm;
  frame_.damping_Nspm = scene_.haptic.damping_Nspm;
  // Without a finger there is nothing to be near: no planes until a device reports one.
  plane_faces_.begin_step(states_.size());
  frame_.plane_count =
      finger_.valid ? features_.extract(plane_query_, states_, period_s_, frame_.planes, &plane_faces_) : 0;
  if (!finger_.valid) frame_.planes.fill(Plane{});
  coupling_->annotate(frame_);
}

double World::mechanical_energy_J() const {
  const Eigen::Vector3d gravity = to_eigen(scene_.gravity_mps2);
  double energy_J = 0.0;
  for (std::size_t id = 0; id < states_.size(); ++id) {
    if (!scene_.objects[id].dynamic) continue;
    const ObjectState& state = states_[id];
    const double mass_kg = scene_.objects[id].mass_kg;
    const Eigen::Matrix3d inertia_world = state.inverse_inertia_world.inverse();
    energy_J += 0.5 * mass_kg * state.velocity_mps.squaredNorm() +
                0.5 * state.angular_velocity_radps.dot(inertia_world * state.angular_velocity_radps) -
                mass_kg * gravity.dot(state.pose.position_m);
  }
  return energy_J;
}

}  // namespace impetus
