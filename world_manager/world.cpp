#include "world_manager/world.h"

#include "world_manager/contact_graph.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace impetus {

namespace {

// Contact points ODE may return per geom pair: box–box needs up to 8 for a face resting on a face.
constexpr int kMaxContactsPerPair = 8;
// Below this approach speed a contact does not bounce: resting and sliding objects would otherwise chatter on every
// substep's tiny penetration-correction velocity (ERP pushes at a few mm/s).
constexpr double kBounceThreshold_mps = 0.05;

void* id_to_data(std::size_t id) { return reinterpret_cast<void*>(static_cast<std::uintptr_t>(id)); }
std::size_t data_to_id(void* data) { return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(data)); }

Eigen::Matrix3d ode_inertia(const dMass& mass) {
  Eigen::Matrix3d inertia;
  // dMatrix3 is row-major 3×4 (one padding column).
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) inertia(r, c) = mass.I[4 * r + c];
  }
  return inertia;
}

}  // namespace

struct World::OdeHandles {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> bodies;    // per object; nullptr for static objects
  std::vector<dGeomID> geoms;     // per object
  std::vector<Material> materials;  // per id, the floor last
  double substep_s = 0.0;
  // Local coupling: the contacts seen in the last substep of a step (contact_graph.h).
  bool record_contacts = false;
  ContactGraph contact_graph;

  ~OdeHandles() {
    if (contacts != nullptr) dJointGroupDestroy(contacts);
    if (space != nullptr) dSpaceDestroy(space);  // destroys the geoms it holds (cleanup mode on)
    if (world != nullptr) dWorldDestroy(world);  // destroys the bodies
  }

  // ODE's near callback: contact joints with the two materials combined (common/scene.h combine_*).
  static void near_callback(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<OdeHandles*>(data);
    dBodyID body_a = dGeomGetBody(a);
    dBodyID body_b = dGeomGetBody(b);
    if (body_a == nullptr && body_b == nullptr) return;  // static against static never moves
    dContact contacts[kMaxContactsPerPair];
    const int count = dCollide(a, b, kMaxContactsPerPair, &contacts[0].geom, sizeof(dContact));
    if (count == 0) return;
    const Material& ma = self->materials[data_to_id(dGeomGetData(a))];
    const Material& mb = self->materials[data_to_id(dGeomGetData(b))];
    const double restitution = combine_restitution(ma.restitution, mb.restitution);
    for (int i = 0; i < count; ++i) {
      dSurfaceParameters& surface = contacts[i].surface;
      // Approx1: the friction bound is mu times the normal force (a Coulomb pyramid). ODE has a single coefficient;
      // it gets the dynamic one because sliding (how far a tapped cube goes, paper §4.2.2) is governed by it. The
      // static coefficient matters for the finger, and the planes carry it to the haptic side.
      surface.mode = dContactApprox1;
      surface.mu = combine_friction(ma.dynamic_friction, mb.dynamic_friction);
      if (restitution > 0.0) {
        surface.mode |= dContactBounce;
        surface.bounce = restitution;
        surface.bounce_vel = kBounceThreshold_mps;
      }
      dJointID joint = dJointCreateContact(self->world, self->contacts, &contacts[i]);
      dJointAttach(joint, body_a, body_b);
      if (self->record_contacts) {
        // ODE's normal points into geom 1 (contact.h): the contact pushes body a along +n and body b along −n.
        const dReal* n = contacts[i].geom.normal;
        const Eigen::Vector3d normal(n[0], n[1], n[2]);
        if (!(normal.squaredNorm() > 0.0) || !normal.allFinite()) continue;
        const auto id_a = static_cast<std::int32_t>(data_to_id(dGeomGetData(a)));
        const auto id_b = static_cast<std::int32_t>(data_to_id(dGeomGetData(b)));
        if (body_a != nullptr) {
          self->contact_graph.add(id_a, body_b != nullptr ? id_b : ContactGraph::kStatic, normal, surface.mu);
        }
        if (body_b != nullptr) {
          self->contact_graph.add(id_b, body_a != nullptr ? id_a : ContactGraph::kStatic, -normal, surface.mu);
        }
      }
    }
  }
};

World::World(const Scene& scene, const WorldOptions& options)
    : scene_(scene),
      options_(options),
      period_s_(1.0 / options.world_rate_hz.value_or(scene.physics.world_rate_hz)),
      stiffness_Npm_(options.position_stiffness_Npm.value_or(scene.haptic.stiffness_Npm)),
      damping_Nspm_(options.position_damping_Nspm.value_or(scene.haptic.damping_Nspm)),
      ode_(std::make_unique<OdeHandles>()),
      random_state_(0),
      states_(scene.objects.size()),
      inverse_inertia_body_(scene.objects.size(), Eigen::Matrix3d::Zero()),
      ledger_(scene.objects.size() + 1),
      moment_ledger_(scene.objects.size() + 1),
      local_impulse_schedule_Ns_(scene.objects.size(),
                                 std::vector<Eigen::Vector3d>(static_cast<std::size_t>(scene.physics.substeps) + 1,
                                                              Eigen::Vector3d::Zero())),
      local_angular_schedule_Nms_(local_impulse_schedule_Ns_),
      features_(scene_),
      step_impulse_Ns_(scene.objects.size(), Eigen::Vector3d::Zero()),
      total_impulse_Ns_(scene.objects.size(), Eigen::Vector3d::Zero()),
      total_angular_impulse_Nms_(scene.objects.size(), Eigen::Vector3d::Zero()),
      coupling_force_N_(scene.objects.size(), Eigen::Vector3d::Zero()),
      coupling_point_m_(scene.objects.size(), Eigen::Vector3d::Zero()) {
  if (options.world_rate_hz && !(*options.world_rate_hz > 0.0 && std::isfinite(*options.world_rate_hz))) {
    throw std::invalid_argument("world rate must be positive and finite, got " +
                                std::to_string(*options.world_rate_hz));
  }
  if (!(stiffness_Npm_ > 0.0) || !std::isfinite(stiffness_Npm_)) {
    throw std::invalid_argument("position-coupling stiffness must be positive, got " + std::to_string(stiffness_Npm_));
  }
  if (!(damping_Nspm_ >= 0.0) || !std::isfinite(damping_Nspm_)) {
    throw std::invalid_argument("position-coupling damping must be non-negative, got " + std::to_string(damping_Nspm_));
  }
  if (options.world_session == 0) throw std::invalid_argument("world_session must be nonzero");
  if (options.coupling != Coupling::impulse && options.coupling != Coupling::position &&
      options.coupling != Coupling::local) {
    throw std::invalid_argument("unknown coupling");
  }

  OdeHandles& ode = *ode_;
  ode.substep_s = period_s_ / scene_.physics.substeps;
  ode.world = dWorldCreate();
  ode.space = dHashSpaceCreate(nullptr);
  ode.contacts = dJointGroupCreate(0);
  dWorldSetGravity(ode.world, scene_.gravity_mps2[0], scene_.gravity_mps2[1], scene_.gravity_mps2[2]);
  dWorldSetERP(ode.world, scene_.physics.erp);
  dWorldSetCFM(ode.world, scene_.physics.cfm);
  dWorldSetQuickStepNumIterations(ode.world, scene_.physics.solver_iterations);
  dWorldSetAutoDisableFlag(ode.world, scene_.physics.auto_disable ? 1 : 0);

  ode.bodies.assign(scene_.objects.size(), nullptr);
  ode.contact_graph.reset(scene_.objects.size());
  ode.geoms.assign(scene_.objects.size(), nullptr);
  for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
    const SceneObject& object = scene_.objects[id];
    const Shape& shape = object.shape;
    dGeomID geom = nullptr;
    dMass mass;
    dMassSetZero(&mass);
    constexpr int kAxisZ = 3;  // ODE's direction code for the body z axis
    switch (shape.kind) {
      case ShapeKind::box:
        geom = dCreateBox(ode.space, shape.box_size_m[0], shape.box_size_m[1], shape.box_size_m[2]);
        if (object.dynamic) {
          dMassSetBoxTotal(&mass, object.mass_kg, shape.box_size_m[0], shape.box_size_m[1], shape.box_size_m[2]);
        }
        break;
      case ShapeKind::sphere:
        geom = dCreateSphere(ode.space, shape.radius_m);
        if (object.dynamic) dMassSetSphereTotal(&mass, object.mass_kg, shape.radius_m);
        break;
      case ShapeKind::capsule:
        geom = dCreateCapsule(ode.space, shape.radius_m, shape.length_m);
        if (object.dynamic) dMassSetCapsuleTotal(&mass, object.mass_kg, kAxisZ, shape.radius_m, shape.length_m);
        break;
      case ShapeKind::cylinder:
        geom = dCreateCylinder(ode.space, shape.radius_m, shape.length_m);
        if (object.dynamic) dMassSetCylinderTotal(&mass, object.mass_kg, kAxisZ, shape.radius_m, shape.length_m);
        break;
    }
    dGeomSetData(geom, id_to_data(id));
    ode.geoms[id] = geom;

    const auto& q = object.orientation_wxyz;
    const dQuaternion orientation{q[0], q[1], q[2], q[3]};
    if (object.dynamic) {
      dBodyID body = dBodyCreate(ode.world);
      dBodySetMass(body, &mass);
      dGeomSetBody(geom, body);
      dBodySetPosition(body, object.position_m[0], object.position_m[1], object.position_m[2]);
      dBodySetQuaternion(body, orientation);
      dBodySetLinearVel(body, object.linear_velocity_mps[0], object.linear_velocity_mps[1],
                        object.linear_velocity_mps[2]);
      dBodySetAngularVel(body, object.angular_velocity_radps[0], object.angular_velocity_radps[1],
                         object.angular_velocity_radps[2]);
      ode.bodies[id] = body;
      inverse_inertia_body_[id] = ode_inertia(mass).inverse();
    } else {
      dGeomSetPosition(geom, object.position_m[0], object.position_m[1], object.position_m[2]);
      dGeomSetQuaternion(geom, orientation);
    }
    ode.materials.push_back(object.material);
  }
  ode.materials.push_back(scene_.floor.material);
  if (scene_.floor.present) {
    dGeomID floor = dCreatePlane(ode.space, 0.0, 0.0, 1.0, scene_.floor.height_m);
    dGeomSetData(floor, id_to_data(scene_.objects.size()));
  }

  // Each World owns a stream of ODE's (global) generator, so QuickStep's constraint shuffling is reproducible.
  dRandSetSeed(static_cast<unsigned long>(scene_.physics.seed));
  random_state_ = dRandGetSeed();

  refresh_states();
  features_.index(states_, period_s_);
  frame_.world_session = options_.world_session;
  frame_.world_period_s = period_s_;
  frame_.coupling = options_.coupling;
  frame_.gravity_mps2 = scene_.gravity_mps2;
  frame_.world_substep_s = ode.substep_s;
  frame_.reach_radius_m = scene_.haptic.reach_radius_m;
}

World::~World() = default;

const PlaneFrame& World::step(const HapticReport* report) {
  // DESIGN.md §1 step 1: the finger, only if a device is attached.
  // Without a new report the last sample stays the latest one.
  if (report != nullptr) {
    finger_valid_ = report->finger_valid != 0 && all_finite(report->finger_m) &&
                    all_finite(report->finger_velocity_mps);
    if (finger_valid_) {
      finger_.position_m = to_eigen(report->finger_m);
      finger_.velocity_mps = to_eigen(report->finger_velocity_mps);
      // Planes come from around the proxy (feature_extractor.h, ReachQuery); a report without a finite proxy
      // falls back to the finger.
      plane_query_ = finger_;
      if (all_finite(report->proxy_m)) {
        plane_query_.position_m = to_eigen(report->proxy_m);
        plane_query_.reach_extra_m = (finger_.position_m - plane_query_.position_m).norm();
      }
    }
  }

  // Step 2: coupling.
  for (auto& impulse : step_impulse_Ns_) impulse.setZero();
  for (auto& force : coupling_force_N_) force.setZero();
  if (report != nullptr) apply_report_impulses(*report);
  if (options_.coupling == Coupling::position && finger_valid_) {
    compute_position_coupling();
  }

  // Step 3.
  advance_ode();
  ++steps_taken_;
  time_s_ = static_cast<double>(steps_taken_) * period_s_;  // no drift from summing periods
  refresh_states();

  // Steps 4 and 5.
  features_.index(states_, period_s_);
  publish(report);
  return frame_;
}

void World::apply_report_impulses(const HapticReport& report) {
  // Impulse coupling applies the differences; position coupling still advances the baselines (so the counters stay
  // in step) but leaves the motion to the penalty force, as the paper's previous method did.
  const bool apply = options_.coupling != Coupling::position;
  const bool local = options_.coupling == Coupling::local;
  // Local coupling places each impulse at the time it was rendered (schedule_local_impulse). The impulses of this
  // report were rendered after the previous report we applied and up to this one: that window maps onto this step.
  const bool known_start = last_report_session_ == report.haptic_session && report.haptic_time_s > last_report_time_s_;
  const double window_s = known_start ? report.haptic_time_s - last_report_time_s_ : period_s_;
  const double window_start_s = report.haptic_time_s - window_s;
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
    ObjectImpulse moments = entry;  // the moments through the same ledger rules (session, epoch, baseline)
    moments.impulse_Ns = entry.impulse_moment_Nss;
    moments.angular_impulse_Nms = entry.angular_impulse_moment_Nmss;
    const ImpulseDelta moment = moment_ledger_.take(owner, moments);
    if (id < floor_id && scene_.objects[id].dynamic) {
      if (local && all_finite(entry.impulse_moment_Nss) && all_finite(entry.angular_impulse_moment_Nmss)) {
        schedule_local_impulse(id, delta, moment, window_start_s, window_s);
      } else if (apply) {
        apply_velocity_change(id, delta.impulse_Ns, delta.angular_impulse_Nms);
      }
    } else {
      total_static_impulse_Ns_ += delta.impulse_Ns;  // the haptic side named static geometry: it absorbs the push
    }
  }
  if (all_finite(report.static_impulse_Ns)) {
    total_static_impulse_Ns_ += ledger_.take_static(owner, report.static_impulse_Ns);
  }
}

void World::apply_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                                  const Eigen::Vector3d& angular_impulse_Nms) {
  // Paper §3.5: v_i = v_{i−1} + F_i/m and I·ω_i = I·ω_{i−1} + L_i, applied as an instantaneous velocity change (not a
  // force over a substep), with the inertia at the current orientation: Δω = I_world⁻¹·L.
  ObjectState& state = states_[id];
  state.velocity_mps += state.inverse_mass_per_kg * impulse_Ns;
  state.angular_velocity_radps += state.inverse_inertia_world * angular_impulse_Nms;
  dBodyID body = ode_->bodies[id];
  dBodySetLinearVel(body, state.velocity_mps.x(), state.velocity_mps.y(), state.velocity_mps.z());
  dBodySetAngularVel(body, state.angular_velocity_radps.x(), state.angular_velocity_radps.y(),
                     state.angular_velocity_radps.z());
  dBodyEnable(body);  // a sleeping body must wake to move
  step_impulse_Ns_[id] += impulse_Ns;
  total_impulse_Ns_[id] += impulse_Ns;
  total_angular_impulse_Nms_[id] += angular_impulse_Nms;
}

void World::schedule_local_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment,
                                   double window_start_s, double window_s) {
  // Local coupling (paper §6.3). The haptic side moved the object tick by tick: an impulse J_k rendered at
  // haptic time t_k has displaced it by J_k·(t_end − t_k)/m by the end of the window. ODE's semi-implicit Euler step
  // gives a force held during substep s (length h) exactly the effect of an impulse at time s·h (v changes at the end
  // of the substep, x then integrates the new v), so the world reproduces both the momentum Σ J_k and the displacement
  // Σ J_k·(t_end − t_k)/m by putting each axis's impulse at its centroid time
  //     c = (Σ J_k·t_k − t_start·Σ J_k) / Σ J_k      (from the report's first moments, link_types.h)
  // split between the two substeps around c: (1 − α) at ⌊c/h⌋ and α at ⌊c/h⌋ + 1, α = frac(c/h). Slot `substeps` is
  // the end of the window (an impulse in the very last tick); it is applied in the last substep (apply_local_schedule).
  // The world's next state then agrees with what the finger felt exactly for a free body (up to h·J/m for an impulse
  // at the very end); with contacts, up to how friction
  // sees the impulse compressed to its centroid (it only acts while the object slides: ≈ 0.3 mm at the start of a
  // tap, while the contact itself is blended, local_dynamics.h).
  const int substeps = scene_.physics.substeps;
  const double h = period_s_ / substeps;
  const double scale = period_s_ / window_s;  // lockstep: 1; real time: the window mapped onto this step
  auto place = [&](double amount, double first_moment, int axis, std::vector<Eigen::Vector3d>& schedule) {
    // Moment about the window's start, mapped onto this step: Σ J_k·c_k with c_k ∈ [0, T_w].
    const double moment = (first_moment - window_start_s * amount) * scale;
    if (!std::isfinite(moment)) {  // cannot place it: all of it after the last substep (velocity only)
      schedule[static_cast<std::size_t>(substeps)][axis] += amount;
      return;
    }
    const double c = amount != 0.0 ? moment / amount : -1.0;
    if (c >= 0.0 && c <= period_s_) {
      const double slots = c / h;
      const int k = std::min(static_cast<int>(std::floor(slots)), substeps);
      const double alpha = k < substeps ? slots - k : 0.0;
      schedule[static_cast<std::size_t>(k)][axis] += (1.0 - alpha) * amount;
      if (alpha > 0.0) schedule[static_cast<std::size_t>(k + 1)][axis] += alpha * amount;
    } else if (amount != 0.0 || moment != 0.0) {
      // The impulse changed sign within the window (its centroid lies outside it, or it summed to zero): split it
      // between the window's ends, b at T_w and a = J − b at 0, with b·T_w = Σ J_k·c_k: still exact in momentum and
      // in displacement for a free body.
      const double at_end = moment / period_s_;
      schedule[0][axis] += amount - at_end;
      schedule[static_cast<std::size_t>(substeps)][axis] += at_end;
    }
  };
  for (int axis = 0; axis < 3; ++axis) {
    place(delta.impulse_Ns[axis], moment.impulse_Ns[axis], axis, local_impulse_schedule_Ns_[id]);
    place(delta.angular_impulse_Nms[axis], moment.angular_impulse_Nms[axis], axis, local_angular_schedule_Nms_[id]);
  }
  dBodyEnable(ode_->bodies[id]);  // a sleeping body must wake to move
  step_impulse_Ns_[id] += delta.impulse_Ns;
  total_impulse_Ns_[id] += delta.impulse_Ns;
  total_angular_impulse_Nms_[id] += delta.angular_impulse_Nms;
}

void World::apply_local_schedule(int slot) {
  // Substep slots: the scheduled impulse as a force held for one substep (ODE clears forces after every step).
  // Slot `substeps` (an impulse at the very end of the window): for a free body, a velocity change after the last
  // substep (exact: no displacement). For a body that touched something at the last frame it goes into the last
  // substep instead, where the contacts see it: as a bare velocity change it would skip them for a whole step (a light
  // ball pushed into the floor in the last tick would sink into it before ODE pushed it back out). The price there is h·J/m of displacement, blended in at the next frame (local_dynamics.h).
  const int substeps = scene_.physics.substeps;
  const double h = period_s_ / substeps;
  for (std::size_t id = 0; id < local_impulse_schedule_Ns_.size(); ++id) {
    Eigen::Vector3d& impulse_Ns = local_impulse_schedule_Ns_[id][static_cast<std::size_t>(slot)];
    Eigen::Vector3d& angular_Nms = local_angular_schedule_Nms_[id][static_cast<std::size_t>(slot)];
    if (slot + 1 == substeps && ode_->contact_graph.touching(static_cast<std::int32_t>(id))) {
      Eigen::Vector3d& end_Ns = local_impulse_schedule_Ns_[id][static_cast<std::size_t>(substeps)];
      Eigen::Vector3d& end_Nms = local_angular_schedule_Nms_[id][static_cast<std::size_t>(substeps)];
      impulse_Ns += end_Ns;
      angular_Nms += end_Nms;
      end_Ns.setZero();
      end_Nms.setZero();
    }
    if (impulse_Ns.isZero(0.0) && angular_Nms.isZero(0.0)) continue;
    dBodyID body = ode_->bodies[id];
    if (slot < substeps) {
      dBodyAddForce(body, impulse_Ns.x() / h, impulse_Ns.y() / h, impulse_Ns.z() / h);
      dBodyAddTorque(body, angular_Nms.x() / h, angular_Nms.y() / h, angular_Nms.z() / h);
    } else {
      const dReal* v = dBodyGetLinearVel(body);
      const dReal* w = dBodyGetAngularVel(body);
      const Eigen::Vector3d velocity = Eigen::Vector3d(v[0], v[1], v[2]) + states_[id].inverse_mass_per_kg * impulse_Ns;
      const Eigen::Vector3d angular =
          Eigen::Vector3d(w[0], w[1], w[2]) + states_[id].inverse_inertia_world * angular_Nms;
      dBodySetLinearVel(body, velocity.x(), velocity.y(), velocity.z());
      dBodySetAngularVel(body, angular.x(), angular.y(), angular.z());
    }
    impulse_Ns.setZero();
    angular_Nms.setZero();
  }
}

void World::attach_local_contacts() {
  // Local coupling: each dynamic object's plane carries the contacts the object had in the last substep, the
  // constraints of the haptic side's local model (link_types.h LocalContact).
  for (std::uint32_t k = 0; k < frame_.plane_count; ++k) {
    Plane& plane = frame_.planes[k];
    plane.local_contact_count = 0;
    if ((plane.flags & kPlaneDynamic) == 0 || plane.object_id < 0) continue;
    const auto id = static_cast<std::size_t>(plane.object_id);
    plane.local_contact_count = ode_->contact_graph.local_contacts(static_cast<std::int32_t>(id), plane.local_contacts);
  }
}

void World::compute_position_coupling() {
  // The paper's previous method (§2.3, fig. 3 "d"): the sampled finger's penetration d into each dynamic object gives
  // a penalty force k_p·d + k_d·ḋ along the inward normal, held for the whole world period. Only the objects near the
  // finger can be penetrated, so the feature index narrows the search.
  std::vector<ReachCandidate> touching;
  features_.within_reach(finger_, states_, 0.0, touching);
  for (const ReachCandidate& candidate : touching) {
    const auto id = static_cast<std::size_t>(candidate.object_id);
    if (id >= scene_.objects.size() || !scene_.objects[id].dynamic) continue;
    const double depth_m = -candidate.surface.signed_distance_m;
    if (depth_m <= 0.0) continue;
    const ObjectState& state = states_[id];
    const Eigen::Vector3d& normal = candidate.surface.normal;
    const Eigen::Vector3d lever_m = candidate.surface.point_m - state.pose.position_m;
    const Eigen::Vector3d surface_velocity_mps = state.velocity_mps + state.angular_velocity_radps.cross(lever_m);
    const double depth_rate_mps = -(finger_.velocity_mps - surface_velocity_mps).dot(normal);
    // A contact can only push: a finger pulling out fast must not drag the object along.
    const double push_N = std::max(0.0, stiffness_Npm_ * depth_m + damping_Nspm_ * depth_rate_mps);
    coupling_force_N_[id] = -push_N * normal;
    coupling_point_m_[id] = candidate.surface.point_m;
    step_impulse_Ns_[id] += coupling_force_N_[id] * period_s_;
    total_impulse_Ns_[id] += coupling_force_N_[id] * period_s_;
    total_angular_impulse_Nms_[id] += lever_m.cross(coupling_force_N_[id]) * period_s_;
  }
}

void World::advance_ode() {
  OdeHandles& ode = *ode_;
  dRandSetSeed(random_state_);
  for (int substep = 0; substep < scene_.physics.substeps; ++substep) {
    // ODE clears accumulated forces after every step, so the held penalty force is added again each substep.
    if (options_.coupling == Coupling::position) {
      for (std::size_t id = 0; id < coupling_force_N_.size(); ++id) {
        const Eigen::Vector3d& force_N = coupling_force_N_[id];
        if (force_N.isZero(0.0)) continue;
        dBodyEnable(ode.bodies[id]);
        const Eigen::Vector3d& point_m = coupling_point_m_[id];
        dBodyAddForceAtPos(ode.bodies[id], force_N.x(), force_N.y(), force_N.z(), point_m.x(), point_m.y(),
                           point_m.z());
      }
    }
    if (options_.coupling == Coupling::local) apply_local_schedule(substep);
    ode.record_contacts = options_.coupling == Coupling::local && substep + 1 == scene_.physics.substeps;
    if (ode.record_contacts) ode.contact_graph.reset(scene_.objects.size());
    dSpaceCollide(ode.space, &ode, &OdeHandles::near_callback);
    if (ode.record_contacts) ode.contact_graph.finish();
    ode.record_contacts = false;
    if (scene_.physics.solver == PhysicsParams::Solver::direct) {
      dWorldStep(ode.world, ode.substep_s);
    } else {
      dWorldQuickStep(ode.world, ode.substep_s);
    }
    dJointGroupEmpty(ode.contacts);
  }
  if (options_.coupling == Coupling::local) apply_local_schedule(scene_.physics.substeps);
  random_state_ = dRandGetSeed();
}

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
    dBodyID body = ode_->bodies[id];
    const dReal* position = dBodyGetPosition(body);
    const dReal* q = dBodyGetQuaternion(body);
    const dReal* velocity = dBodyGetLinearVel(body);
    const dReal* angular = dBodyGetAngularVel(body);
    state.pose.position_m = Eigen::Vector3d(position[0], position[1], position[2]);
    state.pose.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    state.velocity_mps = Eigen::Vector3d(velocity[0], velocity[1], velocity[2]);
    state.angular_velocity_radps = Eigen::Vector3d(angular[0], angular[1], angular[2]);
    state.inverse_mass_per_kg = 1.0 / object.mass_kg;
    const Eigen::Matrix3d rotation = state.pose.orientation.toRotationMatrix();
    state.inverse_inertia_world = rotation * inverse_inertia_body_[id] * rotation.transpose();
  }
}

void World::publish(const HapticReport* report) {
  frame_.frame_index = steps_taken_ - 1;
  if (report != nullptr) {
    frame_.report_tick_applied = report->tick;
    frame_.report_session_applied = report->haptic_session;
  }
  frame_.world_time_s = time_s_;
  frame_.stiffness_Npm = scene_.haptic.stiffness_Npm;
  frame_.damping_Nspm = scene_.haptic.damping_Nspm;
  // Without a finger there is nothing to be near: no planes until a device reports one.
  frame_.plane_count = finger_valid_ ? features_.extract(plane_query_, states_, period_s_, frame_.planes) : 0;
  if (!finger_valid_) frame_.planes.fill(Plane{});
  if (options_.coupling == Coupling::local) attach_local_contacts();
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
