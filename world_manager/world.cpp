// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world.h"

#include "world_manager/deform/press_path.h"
#include "world_manager/engine/engine_registry.h"

#include <algorithm>
#include <array>
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
      applied_(scene.objects.size()),
      endpoints_(kMaxEndpoints),
      frames_(kMaxEndpoints) {
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

  engine_ = make_engine(scene_);
  start_overlaps_ = engine_->overlaps(kStartOverlap_m);
  port_ = std::make_unique<PassivityLayer>(states_, *engine_, options.passivity, to_eigen(scene_.gravity_mps2));
  const CouplingContext context{scene_, period_s_, scene_.physics.substeps, *engine_, states_, applied_, *port_};
  coupling_ = make_coupling(options.coupling, context, stiffness_Npm, damping_Nspm);

  surfaces_.resize(states_.size());
  surface_changes_.assign(states_.size(), 0);
  for (std::size_t id = 0; id < states_.size(); ++id) {
    const SceneObject& object = scene_.objects[id];
    ObjectState& state = states_[id];
    if (!object.dynamic) {
      const auto& q = object.orientation_wxyz;
      state.pose.position_m = to_eigen(object.position_m);
      state.pose.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    }
    if (object.deformable) {
      surfaces_[id] = std::make_unique<DeformableSurface>(*object.deformable, 0.5 * to_eigen(object.shape.box_size_m),
                                                          state.pose.position_m, state.pose.orientation);
    }
  }
  refresh_states(engine_->moved(), false);
  features_.index(states_, period_s_);
  for (PlaneFrame& frame : frames_) {
    frame.world_session = options_.world_session;
    frame.world_period_s = period_s_;
    frame.coupling = options_.coupling;
    frame.gravity_mps2 = scene_.gravity_mps2;
    frame.world_substep_s = period_s_ / scene_.physics.substeps;
    frame.reach_radius_m = scene_.haptic.reach_radius_m;
    frame.port_layer = options.passivity ? 1 : 0;
  }
  port_pushers_.reserve(static_cast<std::size_t>(kMaxEndpoints) * kMaxImpulseEntries);
}

World::~World() = default;

std::span<const PlaneFrame> World::step(std::span<const HapticReport* const> reports) {
  if (reports.size() > kMaxEndpoints) {
    throw std::invalid_argument("a world serves at most " + std::to_string(kMaxEndpoints) + " endpoints, not " +
                                std::to_string(reports.size()));
  }
  slots_used_ = reports.size();
  // Step 1: each slot's finger, only where a device is attached. Without a new report the last sample stays the
  // latest one. A slot taken over by another endpoint (a controller restarted, another user) starts afresh.
  for (std::size_t slot = 0; slot < reports.size(); ++slot) {
    const HapticReport* report = reports[slot];
    if (report == nullptr) continue;
    Endpoint& endpoint = endpoints_[slot];
    if (report->haptic_session != endpoint.haptic_session || report->endpoint != endpoint.endpoint) {
      endpoint.haptic_session = report->haptic_session;
      endpoint.endpoint = report->endpoint;
      endpoint.finger = FingerState{};
      endpoint.plane_query_known = false;
      endpoint.plane_faces = FeatureMemory{};
    }
    take_finger(endpoint, *report);
  }

  // Step 2: the coupling. Only totals counted against this world's own frames: a report counted against another
  // world session (a world that died, or none yet) carries impulse this world never showed, and its objects started
  // afresh from the scene. Slots are taken in order, so a run is reproducible whatever the reports hold.
  applied_.begin_step();
  std::array<const HapticReport*, kMaxEndpoints> applied{};
  for (std::size_t slot = 0; slot < reports.size(); ++slot) {
    const HapticReport* report = reports[slot];
    if (report == nullptr) continue;
    if (report->world_session != options_.world_session) {
      ++foreign_reports_;
      // A haptic side that has seen no world yet (session 0) and rendered nothing has nothing to apply, and all of
      // it is in this step: its frame names the report, so the haptic side measures the link's round trip from
      // its first frame (HapticReport::link_round_trip_s), a round trip sooner than from the first applied one.
      if (report->world_session == 0 && report->entry_count == 0) applied[slot] = report;
      continue;
    }
    applied[slot] = report;
    take_report(endpoints_[slot], *report);
  }
  for (std::size_t slot = 0; slot < kMaxEndpoints; ++slot) {
    fingers_[slot] = slot < reports.size() ? endpoints_[slot].finger : FingerState{};
  }
  // The penetration rule moves the surface by the finger as sampled now (the previous method of paper §6.4); an
  // elastic one follows the proxy, where the haptic side holds the finger's contact.
  for (const auto& surface : surfaces_) {
    if (!surface || surface->material().rule != DeformableMaterial::Rule::penetration) continue;
    const bool elastic = surface->material().law == DeformableMaterial::Law::elastic;
    for (std::size_t slot = 0; slot < reports.size(); ++slot) {
      if (!fingers_[slot].valid) continue;
      surface->press_by_penetration(
          elastic ? endpoints_[slot].plane_query.position_m : fingers_[slot].finger.position_m, slot);
    }
  }
  coupling_->before_step(std::span<const FingerState>(fingers_.data(), reports.size()), features_);
  port_->settle();  // the velocity changes the reports made, against the hand input they brought

  // Step 3: the engine, with the coupling's forces before every substep (and the port's books after each).
  engine_->step(scene_.physics.substeps, period_s_ / scene_.physics.substeps, coupling_->needs_contacts(), *coupling_);
  coupling_->after_step();
  port_->settle();
  hand_back_unspent();
  // Deformable surfaces yield; bodies rest on the dented surface from the next step on.
  for (std::size_t id = 0; id < surfaces_.size(); ++id) {
    DeformableSurface* surface = surfaces_[id].get();
    if (surface == nullptr) continue;
    surface->yield_period(period_s_);
    if (surface->changes() != surface_changes_[id]) {
      surface_changes_[id] = surface->changes();
      engine_->dent_top(id, surface->dented_top());
    }
  }
  ++steps_taken_;
  time_s_ = static_cast<double>(steps_taken_) * period_s_;  // no drift from summing periods
  refresh_states(engine_->moved(), true);
  simulated_object_steps_ += engine_->moved().size();
  if (scene_.floor.present) {
    for (const std::size_t id : engine_->moved()) {
      // The lowest point: the support along −z in the body frame (exact for any shape, also off-centre meshes).
      const BodyPose& pose = states_[id].pose;
      const Eigen::Vector3d down_body = pose.orientation.conjugate() * -Eigen::Vector3d::UnitZ();
      const double lowest_m = pose.position_m.z() - support_m(scene_.objects[id].shape, down_body);
      floor_penetration_max_m_ = std::max(floor_penetration_max_m_, scene_.floor.height_m - lowest_m);
    }
  }

  // Step 4: planes and publication.
  features_.reindex(states_, period_s_, engine_->moved());
  for (std::size_t slot = 0; slot < reports.size(); ++slot) publish(slot, applied[slot]);
  return {frames_.data(), reports.size()};
}

void World::hand_back_unspent() {
  if (port_pushers_.empty()) return;
  // By object, then slot: the same order whatever order the reports came in.
  std::sort(port_pushers_.begin(), port_pushers_.end(), [](const PortPusher& a, const PortPusher& b) {
    return a.id != b.id ? a.id < b.id : a.slot < b.slot;
  });
  for (std::size_t first = 0; first < port_pushers_.size();) {
    std::size_t last = first;
    double weight_Ns = 0.0;
    while (last < port_pushers_.size() && port_pushers_[last].id == port_pushers_[first].id) {
      weight_Ns += port_pushers_[last++].weight_Ns;
    }
    const double unspent_J = port_->return_unspent(port_pushers_[first].id);
    if (unspent_J > 0.0) {
      for (std::size_t k = first; k < last; ++k) {
        returned_J_[port_pushers_[k].slot] += unspent_J * port_pushers_[k].weight_Ns / weight_Ns;
      }
    }
    first = last;
  }
  port_pushers_.clear();
}

void World::take_finger(Endpoint& endpoint, const HapticReport& report) {
  FingerState& finger = endpoint.finger;
  finger.valid = report.finger_valid != 0 && all_finite(report.finger_m) && all_finite(report.finger_velocity_mps);
  if (!finger.valid) return;
  finger.finger.position_m = to_eigen(report.finger_m);
  finger.finger.velocity_mps = to_eigen(report.finger_velocity_mps);
  // Planes come from around the proxy (feature_extractor.h, ReachQuery); a report without a finite proxy falls back
  // to the finger.
  endpoint.plane_query = finger.finger;
  endpoint.plane_query_known = true;
  // The link's round trip, as the haptic side measured it, up to the longest a link may hold (kMaxRoundTrip_s).
  if (std::isfinite(report.link_round_trip_s)) {
    endpoint.plane_query.round_trip_s = std::clamp(report.link_round_trip_s, 0.0, kMaxRoundTrip_s);
  }
  if (all_finite(report.proxy_m)) {
    endpoint.plane_query.position_m = to_eigen(report.proxy_m);
    endpoint.plane_query.reach_extra_m = (finger.finger.position_m - endpoint.plane_query.position_m).norm();
  }
}

void World::take_report(Endpoint& endpoint, const HapticReport& report) {
  // The impulses of this report were rendered after the previous report applied and up to this one: that window
  // maps onto this step (local coupling places each impulse in it).
  const bool known_start =
      endpoint.last_report_session == report.haptic_session && report.haptic_time_s > endpoint.last_report_time_s;
  RenderWindow window;
  window.length_s = known_start ? report.haptic_time_s - endpoint.last_report_time_s : period_s_;
  window.start_s = report.haptic_time_s - window.length_s;
  if (known_start && report.tick > endpoint.last_report_tick) {
    window.tick_s = window.length_s / static_cast<double>(report.tick - endpoint.last_report_tick);
  }
  // The world time this report covers: since the endpoint's previous new report was applied, or one step for its
  // first. A report seen again (a transport keeps the last one while its controller is silent) brings nothing and
  // leaves that time alone, so the report after a silence covers the whole of it.
  const double covered_world_s = known_start ? time_s_ - endpoint.last_applied_world_time_s : period_s_;
  // The wall time the world did not simulate since then (its clock skipped steps: a stall).
  const double stalled_s = known_start ? stalled_s_ - endpoint.stalled_at_last_applied_s : 0.0;
  const bool new_report = known_start || endpoint.last_report_session != report.haptic_session;
  if (new_report) {
    endpoint.last_applied_world_time_s = time_s_;
    endpoint.stalled_at_last_applied_s = stalled_s_;
  }
  endpoint.last_report_session = report.haptic_session;
  endpoint.last_report_time_s = report.haptic_time_s;
  endpoint.last_report_tick = report.tick;
  const std::size_t floor_id = scene_.objects.size();
  const CounterOwner owner{report.haptic_session, report.endpoint};
  std::vector<Eigen::Vector3d>& applied = applied_by_owner_[owner];
  if (applied.empty()) applied.assign(floor_id + 1, Eigen::Vector3d::Zero());
  const std::uint32_t count = std::min(report.entry_count, kMaxImpulseEntries);
  // The new impulse of each entry (the ledger's differences), before anything is applied.
  struct Taken {
    std::size_t id;
    ImpulseDelta delta;
    ImpulseDelta moment;
    bool moment_finite;
  };
  std::array<Taken, kMaxImpulseEntries> taken;
  std::uint32_t taken_count = 0;
  Eigen::Vector3d reaction_Ns = Eigen::Vector3d::Zero();  // Σ ΔJ: the finger's reaction, static geometry's share too
  double reaction_sum_Ns = 0.0;                           // Σ|ΔJ| over its shares
  for (std::uint32_t i = 0; i < count; ++i) {
    const ObjectImpulse& entry = report.entries[i];
    if (entry.object_id < 0 || static_cast<std::size_t>(entry.object_id) > floor_id ||
        !all_finite(entry.impulse_Ns) || !all_finite(entry.angular_impulse_Nms)) {
      ++rejected_entries_;
      continue;
    }
    const auto id = static_cast<std::size_t>(entry.object_id);
    ObjectImpulse moments = entry;  // the moments through the same ledger rules (owner, epoch, baseline)
    moments.impulse_Ns = entry.impulse_moment_Nss;
    moments.angular_impulse_Nms = entry.angular_impulse_moment_Nmss;
    Taken& t = taken[taken_count++];
    t = {id, ledger_.take(owner, entry), moment_ledger_.take(owner, moments),
         all_finite(entry.impulse_moment_Nss) && all_finite(entry.angular_impulse_moment_Nmss)};
    reaction_Ns += t.delta.impulse_Ns;
    reaction_sum_Ns += t.delta.impulse_Ns.norm();
  }
  Eigen::Vector3d static_delta_Ns = Eigen::Vector3d::Zero();
  if (all_finite(report.static_impulse_Ns)) static_delta_Ns = ledger_.take_static(owner, report.static_impulse_Ns);
  reaction_Ns += static_delta_Ns;
  reaction_sum_Ns += static_delta_Ns.norm();
  // What a device can have put in: its force limit over the time the report's rendering may stand for in this step,
  // |Σ ΔJ| ≤ F_max·T, the reaction split among the contacts by at most kMaxReactionSplitRatio (Σ|ΔJ| ≤ √3·|reaction|
  // for ≤ 3 constraints, haptic_controller/impulse_accumulator.cpp). T is the haptic time the report covers (its
  // window) less the wall time the world stalled through: after a stall the controller has rendered against a plane
  // that did not move, but the world simulates one step, and more than F_max·T_w in it would be a force the device
  // cannot make, doing work nobody put in. Timing that only shifts (a world step woken late, a report read older or
  // fresher than the last; the next report covers that much less or more) is not a stall: its whole window goes in.
  // T is at least one step (a first report, a short window) and at most the world time covered plus one step (a
  // rogue haptic time). The excess is cut from every share alike, dropped and counted: the world receives less,
  // never more.
  constexpr double kMaxReactionSplitRatio = 1.7320508075688772;
  constexpr double kRounding = 1.0 + 1e-9;  // sums of a tick's worth of rounding
  const double rendered_s = known_start ? window.length_s - stalled_s : period_s_;
  const double limit_s = std::max(std::min(rendered_s, covered_world_s + period_s_), period_s_);
  const double limit_Ns = options_.report_force_limit_N * limit_s * kRounding;
  double scale = 1.0;
  if (reaction_Ns.norm() > limit_Ns) scale = limit_Ns / reaction_Ns.norm();
  if (reaction_sum_Ns > kMaxReactionSplitRatio * limit_Ns) {
    scale = std::min(scale, kMaxReactionSplitRatio * limit_Ns / reaction_sum_Ns);
  }
  if (scale < 1.0) {
    ++clipped_reports_;
    clipped_impulse_Ns_ += (1.0 - scale) * reaction_sum_Ns;
  }
  for (std::uint32_t i = 0; i < taken_count; ++i) {
    Taken& t = taken[i];
    if (scale < 1.0) {
      t.delta.impulse_Ns *= scale;
      t.delta.angular_impulse_Nms *= scale;
      t.delta.press = t.delta.press.scaled(scale);
      t.moment.impulse_Ns *= scale;
      t.moment.angular_impulse_Nms *= scale;
    }
    const std::size_t id = t.id;
    // The hand's input counts whole, clipped or not: the hand put it in.
    if (id < floor_id && scene_.objects[id].dynamic) {
      port_->add_hand_input(id, t.delta.hand_input_J);
      const double weight_Ns = t.delta.impulse_Ns.norm();
      if (port_->enabled() && weight_Ns > 0.0) {
        port_pushers_.push_back({id, static_cast<std::size_t>(&endpoint - endpoints_.data()), weight_Ns});
      }
    }
    // Position coupling moves nothing by the reports (its penalty comes from the sampled finger): nothing applied.
    if (options_.coupling != Coupling::position) applied[id] += t.delta.impulse_Ns;
    // An entry whose total has not grown since the last report brings nothing new: handing it on would only wake a
    // sleeping object the finger touched once and left.
    const bool nothing_new = t.delta.impulse_Ns.isZero(0.0) && t.delta.angular_impulse_Nms.isZero(0.0) &&
                             t.moment.impulse_Ns.isZero(0.0) && t.moment.angular_impulse_Nms.isZero(0.0);
    if (nothing_new) continue;
    if (id < floor_id && surfaces_[id]) {
      surfaces_[id]->absorb(t.delta.impulse_Ns);
      // The push beyond yield, where and when it was given (deform/press_path.h).
      if (surfaces_[id]->material().rule == DeformableMaterial::Rule::impulse) {
        surfaces_[id]->press(stroke_of(t.delta.press), static_cast<std::size_t>(&endpoint - endpoints_.data()));
      }
    }
    if (id < floor_id && scene_.objects[id].dynamic) {
      coupling_->take_impulse(id, t.delta, t.moment, t.moment_finite, window);
    } else {
      total_static_impulse_Ns_ += t.delta.impulse_Ns;  // the haptic side named static geometry: it absorbs the push
    }
  }
  total_static_impulse_Ns_ += scale * static_delta_Ns;
}

Eigen::Vector3d World::applied_by(const CounterOwner& owner, std::size_t id) const {
  const auto found = applied_by_owner_.find(owner);
  return found != applied_by_owner_.end() && id < found->second.size() ? found->second[id] : Eigen::Vector3d::Zero();
}

std::vector<CounterOwner> World::impulse_owners() const {
  std::vector<CounterOwner> owners;
  for (const auto& [owner, impulses] : applied_by_owner_) owners.push_back(owner);
  return owners;
}

const std::vector<std::size_t>& World::escaped() const { return engine_->escaped(); }

void World::refresh_states(std::span<const std::size_t> moved, bool stepped) {
  // A body that did not move has no acceleration: only those that moved last time can hold one (a step costs the
  // bodies that move, not the bodies that exist).
  for (const std::size_t id : accelerated_) states_[id].acceleration_mps2.setZero();
  accelerated_.assign(moved.begin(), moved.end());
  for (const std::size_t id : moved) {
    ObjectState& state = states_[id];
    const SceneObject& object = scene_.objects[id];
    const Eigen::Vector3d velocity_before_mps = state.velocity_mps;
    engine_->read_state(id, state);
    if (stepped) state.acceleration_mps2 = (state.velocity_mps - velocity_before_mps) / period_s_;
    state.inverse_mass_per_kg = 1.0 / object.mass_kg;
    const Eigen::Matrix3d rotation = state.pose.orientation.toRotationMatrix();
    state.inverse_inertia_world = rotation * engine_->inverse_inertia_body(id) * rotation.transpose();
  }
}

void World::publish(std::size_t slot, const HapticReport* applied_report) {
  Endpoint& endpoint = endpoints_[slot];
  PlaneFrame& frame = frames_[slot];
  frame.frame_index = steps_taken_ - 1;
  frame.endpoint = endpoint.endpoint;
  if (applied_report != nullptr) {
    frame.report_tick_applied = applied_report->tick;
    frame.report_session_applied = applied_report->haptic_session;
  }
  frame.world_time_s = time_s_;
  frame.port_returned_J = returned_J_[slot];
  frame.stiffness_Npm = scene_.haptic.stiffness_Npm;
  frame.damping_Nspm = scene_.haptic.damping_Nspm;
  // Planes are taken around the finger's proxy, and, while the finger is absent (a device gone for a moment, a web
  // page silent, a report gone stale), around where it was last: a finger that comes back finds the surfaces it left
  // at once, and the haptic side resumes a press instead of letting the finger sink until the world has heard of it
  // again (haptic_controller/god_object.h); and the faces the proxy met stay remembered, so a finger that went on
  // moving while its device stalled meets the face it went in by, not the far face of a memory that lapsed. Before
  // any finger was reported there is nothing to be near: no planes.
  const bool near_finger = endpoint.plane_query_known;
  if (near_finger) endpoint.plane_faces.begin_step(states_.size());
  const std::uint32_t used_before = std::min(frame.plane_count, kMaxPlanes);
  frame.plane_count =
      near_finger ? features_.extract(endpoint.plane_query, states_, period_s_, frame.planes, &endpoint.plane_faces)
                  : 0;
  // A deformable object's top face is its grid's, dented: the plane under the proxy, good within the contact pad, and
  // (the nearest such object's) the heights around it, from which the haptic side takes the plane again every tick.
  // Its other faces are a fixed box's, whose pushes dent nothing.
  frame.dent_patch = DentPatch{};
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    Plane& plane = frame.planes[k];
    if (plane.object_id < 0 || static_cast<std::size_t>(plane.object_id) >= surfaces_.size()) continue;
    const DeformableSurface* surface = surfaces_[static_cast<std::size_t>(plane.object_id)].get();
    if (surface == nullptr) continue;
    const Eigen::Vector3d query_body_m = surface->to_body(endpoint.plane_query.position_m);
    if (!surface->over_face(query_body_m)) continue;
    plane.flags |= kPlaneDeformable;
    const DeformableMaterial& material = surface->material();
    plane.yield_force_N = material.yield_force_N();
    plane.yield_depth_mpNs = material.yield_depth_mpNs();
    plane.yield_radius_m = material.contact_radius_m;
    Eigen::Vector3d point_m, normal;
    surface->tangent_plane(query_body_m, point_m, normal);
    plane.yield_room_m = surface->room_m(query_body_m.x(), query_body_m.y());
    plane.yield_compliance_mpN = surface->compliance_mpN();
    plane.point_m = to_vec3(point_m);
    plane.normal = to_vec3(normal);
    plane.shape = Shape{};
    plane.body_axis_x = {};
    plane.body_axis_y = {};
    plane.extent_m = surface->material().contact_radius_m;
    // The patch reaches as far as the finger goes in two periods along the face: until the next frame, and one
    // more should that frame be late.
    const Eigen::Vector3d up = to_eigen(plane.normal);
    const Eigen::Vector3d velocity_mps = endpoint.plane_query.velocity_mps;
    const double travel_m = 2.0 * period_s_ * (velocity_mps - velocity_mps.dot(up) * up).norm();
    if (frame.dent_patch.object_id < 0) {
      surface->patch_about(query_body_m, plane.object_id, travel_m, frame.dent_patch, slot);
    }
  }
  // Planes past the count stay value-initialised (frames.h copy_used): only those the last frame used need it.
  for (std::uint32_t k = frame.plane_count; k < used_before; ++k) frame.planes[k] = Plane{};
  coupling_->annotate(frame);
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
