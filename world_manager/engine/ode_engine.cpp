// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/ode_engine.h"

#include "world_manager/engine/escape_guard.h"
#include "world_manager/engine/speculative_contact.h"
#include "world_manager/features/spatial_grid.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace impetus {
namespace {

// Contact points ODE may return per geom pair: box–box needs up to 8 for a face resting on a face.
constexpr int kMaxContactsPerPair = 8;
// Below this approach speed a contact does not bounce: resting and sliding objects would otherwise chatter on every
// substep's tiny penetration-correction velocity (ERP pushes at a few mm/s).
constexpr double kBounceThreshold_mps = 0.05;

// Sleeping (ode_engine.h): a body sleeps once its speeds have stayed under these for kRestBeforeSleep_s. ODE's own
// defaults for the speeds (0.01 m/s, 0.01 rad/s: a 5 cm cube's corner moves 0.25 mm/s) are far below anything the
// haptic side renders. Half a second is ten 20 Hz world periods: a body bouncing or rocking to rest is not frozen
// mid-motion, and one that a finger keeps pushing is woken by each push (RigidBodyEngine::wake).
constexpr double kSleepSpeed_mps = 0.01;
constexpr double kSleepAngularSpeed_radps = 0.01;
constexpr double kRestBeforeSleep_s = 0.5;

Eigen::AlignedBox3d geom_bounds(dGeomID geom) {
  dReal aabb[6];
  dGeomGetAABB(geom, aabb);  // ODE's order: min x, max x, min y, max y, min z, max z
  return Eigen::AlignedBox3d(Eigen::Vector3d(aabb[0], aabb[2], aabb[4]), Eigen::Vector3d(aabb[1], aabb[3], aabb[5]));
}

// The median object extent: a grid cell then holds a few objects and an object spans a few cells.
double grid_cell_size_m(const Scene& scene) {
  std::vector<double> extents_m;
  for (const SceneObject& object : scene.objects) extents_m.push_back(largest_extent_m(object.shape));
  if (extents_m.empty()) return 1.0;
  auto middle = extents_m.begin() + static_cast<std::ptrdiff_t>(extents_m.size() / 2);
  std::nth_element(extents_m.begin(), middle, extents_m.end());
  return *middle;
}

// A geom pair as one key, the lower id first (the floor's id is the object count).
std::uint64_t pair_key(std::size_t a, std::size_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
}

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

struct OdeEngine::Handles final : EscapeGuard::Engine {
  const Scene* scene = nullptr;
  dWorldID world = nullptr;
  dSpaceID space = nullptr;  // with sleeping: the awake geoms only
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> bodies;      // per object; nullptr for static objects and sleeping bodies
  std::vector<dGeomID> geoms;       // per object
  std::vector<Material> materials;  // per id, the floor last
  std::vector<Eigen::Matrix3d> inverse_inertia_body;  // per object; zero for static ones
  unsigned long random_state = 0;   // ODE's generator state between this engine's steps
  bool record_contacts = false;
  ContactGraph contact_graph;
  // The contacts of the recording substep, kept until the step has computed their forces.
  struct RecordedContact {
    dJointID joint;
    std::int32_t id_a, id_b;  // kStatic for a side without a body
    Eigen::Vector3d normal;   // pushes a out of b
    double friction;
    bool speculative;         // a pair not touching yet: in the graph only if the step pressed it
  };
  std::vector<RecordedContact> recorded;
  std::vector<dJointFeedback> feedback;  // one per recorded contact; sized before the step so the addresses hold
  EscapeGuard escape_guard{0};           // objects taken out of the simulation (park_escaped)
  std::vector<std::size_t> moved;        // RigidBodyEngine::moved()

  // Speculative contacts (speculative_contact.h, scene physics.speculative_contacts).
  bool speculative = false;
  std::vector<Eigen::Vector3d> displacement;   // per object: its free displacement in this substep (awake bodies)
  double substep_s = 0.0;                      // the substep being made
  std::vector<std::uint64_t> touching;         // pair_key of every pair with ordinary contacts in this substep
  struct Sweep {
    std::size_t id;
    Eigen::AlignedBox3d bounds;
  };
  std::vector<Sweep> sweeps;                   // scratch: the moving bodies' swept bounds
  std::vector<std::pair<std::size_t, Eigen::AlignedBox3d>> fixed_bounds;  // without sleeping: fixed objects' geoms
  std::vector<std::pair<dGeomID, dGeomID>> closing;  // touching pairs still closing fast (near_callback)

  // Sleeping (ode_engine.h). The awake list is in the order bodies woke; `moved` is sorted at the end of each step.
  bool sleeping = false;
  dSpaceID resting_space = nullptr;  // owns the geoms of static objects, sleeping bodies and the floor
  dGeomID floor = nullptr;                    // in resting_space with sleeping, else in space
  enum class Kind : std::uint8_t { fixed, awake, asleep };
  std::vector<Kind> kind;                     // per object
  std::vector<std::size_t> awake;             // ids of the awake dynamic bodies (not escaped)
  std::vector<dMass> masses;                  // per object, to rebuild a body that wakes
  struct RestingPose {
    dVector3 position;
    dQuaternion orientation;
  };
  std::vector<RestingPose> resting_pose;      // per object, while it sleeps
  std::vector<Eigen::AlignedBox3d> resting_bounds;  // per object in the grid: its geom's box
  std::unique_ptr<SpatialGrid> grid;          // fixed geometry and sleeping bodies
  std::vector<std::size_t> wake_queue;        // scratch
  std::vector<std::int32_t> nearby;           // scratch

  // Puts dynamic object `id`, which ODE has disabled, to sleep: out of ODE, its geom fixed where the body rests.
  void fall_asleep(std::size_t id) {
    dBodyID body = bodies[id];
    dGeomID geom = geoms[id];
    RestingPose& pose = resting_pose[id];
    const dReal* p = dBodyGetPosition(body);
    const dReal* q = dBodyGetQuaternion(body);
    std::copy(p, p + 3, pose.position);
    std::copy(q, q + 4, pose.orientation);
    dGeomSetBody(geom, nullptr);
    dGeomSetPosition(geom, pose.position[0], pose.position[1], pose.position[2]);
    dGeomSetQuaternion(geom, pose.orientation);
    dBodyDestroy(body);
    bodies[id] = nullptr;
    dSpaceRemove(space, geom);
    dSpaceAdd(resting_space, geom);
    kind[id] = Kind::asleep;
    resting_bounds[id] = geom_bounds(geom);
    grid->update(static_cast<std::int32_t>(id), resting_bounds[id]);
    contact_graph.rest(static_cast<std::int32_t>(id));
  }

  // Wakes sleeping object `id`: a new body with its mass, at its resting pose, at rest.
  void wake_up(std::size_t id) {
    dGeomID geom = geoms[id];
    const RestingPose& pose = resting_pose[id];
    dBodyID body = dBodyCreate(world);
    dBodySetMass(body, &masses[id]);
    dBodySetPosition(body, pose.position[0], pose.position[1], pose.position[2]);
    dBodySetQuaternion(body, pose.orientation);
    dGeomSetBody(geom, body);
    bodies[id] = body;
    grid->remove(static_cast<std::int32_t>(id));
    dSpaceRemove(resting_space, geom);
    dSpaceAdd(space, geom);
    kind[id] = Kind::awake;
    awake.push_back(id);
    const auto at = std::lower_bound(moved.begin(), moved.end(), id);
    if (at == moved.end() || *at != id) moved.insert(at, id);
    contact_graph.wake(static_cast<std::int32_t>(id));
  }

  // Wakes every sleeping body an awake one touches, and those they touch in turn (ODE's islands would). With
  // speculative contacts also those an awake body would reach within the substep of h, so that they meet as bodies.
  void wake_touched(double h) {
    wake_queue.assign(awake.begin(), awake.end());
    for (std::size_t i = 0; i < wake_queue.size(); ++i) {
      const std::size_t id = wake_queue[i];
      if (escape_guard.escaped(id)) continue;
      dGeomID geom = geoms[id];
      Eigen::AlignedBox3d bounds = geom_bounds(geom);
      if (speculative) {
        displacement[id] = free_displacement(id, h);
        Eigen::AlignedBox3d moved_bounds = bounds;
        bounds.extend(moved_bounds.translate(displacement[id]));
      }
      grid->query(bounds, nearby);
      for (const std::int32_t other : nearby) {
        const auto o = static_cast<std::size_t>(other);
        if (kind[o] != Kind::asleep || !bounds.intersects(resting_bounds[o])) continue;
        dContact touch[kMaxContactsPerPair];
        if (dCollide(geom, geoms[o], 1, &touch[0].geom, sizeof(dContact)) == 0 &&
            !(speculative && speculative_contacts(geom, bodies[id], geoms[o], displacement[id], touch,
                                                  kMaxContactsPerPair) > 0)) {
          continue;
        }
        wake_up(o);
        wake_queue.push_back(o);
      }
    }
  }

  // Contacts of the awake geoms: among themselves (the space), with the floor and with fixed geometry (the grid).
  // Sleeping bodies an awake one touches were woken first (wake_touched), so none is met here.
  void collide_awake() {
    dSpaceCollide(space, this, &Handles::near_callback);
    for (const std::size_t id : awake) {
      if (escape_guard.escaped(id)) continue;
      dGeomID geom = geoms[id];
      if (floor != nullptr) near_callback(this, geom, floor);
      const Eigen::AlignedBox3d bounds = geom_bounds(geom);
      grid->query(bounds, nearby);
      for (const std::int32_t other : nearby) {
        const auto o = static_cast<std::size_t>(other);
        if (kind[o] == Kind::fixed && bounds.intersects(resting_bounds[o])) near_callback(this, geom, geoms[o]);
      }
    }
  }

  // After a step: the bodies ODE disabled go to sleep.
  void put_rested_to_sleep() {
    std::size_t kept = 0;
    for (const std::size_t id : awake) {
      if (escape_guard.escaped(id)) continue;
      if (dBodyIsEnabled(bodies[id]) == 0) {
        fall_asleep(id);
        continue;
      }
      awake[kept++] = id;
    }
    awake.resize(kept);
  }

  // Takes every body the solver has thrown out of range out of the simulation before the broadphase sees it (ODE's
  // hash space asserts on coordinates it cannot store in its cells): escape_guard.h decides, park() does.
  void park_escaped() {
    if (sleeping) {
      escape_guard.check(awake, *this);
      return;
    }
    escape_guard.check_all(*this);
  }
  std::optional<EscapeGuard::BodyState> escape_state(std::size_t id) const override {
    dBodyID body = bodies[id];
    if (body == nullptr) return std::nullopt;
    const dReal* p = dBodyGetPosition(body);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    const dReal* q = dBodyGetQuaternion(body);  // w, x, y, z
    return EscapeGuard::BodyState{Eigen::Vector3d(p[0], p[1], p[2]), Eigen::Vector3d(v[0], v[1], v[2]),
                                  Eigen::Vector3d(w[0], w[1], w[2]), Eigen::Vector4d(q[0], q[1], q[2], q[3])};
  }
  void park(std::size_t id, const Eigen::Vector3d& position_m, bool reset_orientation) override {
    dBodyID body = bodies[id];
    if (reset_orientation) {
      const dQuaternion identity{1.0, 0.0, 0.0, 0.0};
      dBodySetQuaternion(body, identity);
    }
    dBodySetPosition(body, position_m.x(), position_m.y(), position_m.z());
    dBodySetLinearVel(body, 0.0, 0.0, 0.0);
    dBodySetAngularVel(body, 0.0, 0.0, 0.0);
    dBodySetGravityMode(body, 0);
    dBodyDisable(body);
    dGeomDisable(geoms[id]);
  }

  ~Handles() {
    if (contacts != nullptr) dJointGroupDestroy(contacts);
    if (resting_space != nullptr) dSpaceDestroy(resting_space);
    if (space != nullptr) dSpaceDestroy(space);  // destroys the geoms it holds (cleanup mode on)
    if (world != nullptr) dWorldDestroy(world);  // destroys the bodies
  }

  // The recorded contacts into the graph, each with the normal force the step found: |f·n| of the force the joint put
  // on its first body (the normal component is the same, opposite, on the other; friction is perpendicular to n).
  void record_graph() {
    contact_graph.reset(scene->objects.size());
    for (std::size_t c = 0; c < recorded.size(); ++c) {
      const RecordedContact& contact = recorded[c];
      const dReal* f = feedback[c].f1;
      const double normal_force_N = std::abs(contact.normal.dot(Eigen::Vector3d(f[0], f[1], f[2])));
      if (contact.speculative && !(normal_force_N > 0.0)) continue;  // the pair did not meet in the substep
      if (contact.id_a != ContactGraph::kStatic) {
        contact_graph.add(contact.id_a, contact.id_b, contact.normal, contact.friction, normal_force_N);
      }
      if (contact.id_b != ContactGraph::kStatic) {
        contact_graph.add(contact.id_b, contact.id_a, -contact.normal, contact.friction, normal_force_N);
      }
    }
    contact_graph.finish();
  }

  // The two materials combined (scene.h combine_*) on a contact's surface.
  void set_surface(dSurfaceParameters& surface, const Material& ma, const Material& mb) const {
    // Approx1: the friction bound is mu times the normal force (a Coulomb pyramid). ODE has a single coefficient;
    // it gets the dynamic one because sliding (how far a tapped cube goes, paper §4.2.2) is governed by it. The
    // static coefficient matters for the finger, and the planes carry it to the haptic side.
    surface.mode = dContactApprox1;
    surface.mu = combine_friction(ma.dynamic_friction, mb.dynamic_friction);
    const double restitution = combine_restitution(ma.restitution, mb.restitution);
    if (restitution > 0.0) {
      surface.mode |= dContactBounce;
      surface.bounce = restitution;
      surface.bounce_vel = kBounceThreshold_mps;
    }
  }

  // A contact joint between the geoms' bodies, recorded for the contact graph in the recording substep.
  void add_contact(const dContact& contact, dGeomID a, dGeomID b, bool speculative_contact) {
    dBodyID body_a = dGeomGetBody(a);
    dBodyID body_b = dGeomGetBody(b);
    dJointID joint = dJointCreateContact(world, contacts, &contact);
    dJointAttach(joint, body_a, body_b);
    if (!record_contacts) return;
    // ODE's normal points into geom 1 (contact.h): the contact pushes body a along +n and body b along −n.
    const dReal* n = contact.geom.normal;
    const Eigen::Vector3d normal(n[0], n[1], n[2]);
    if (!(normal.squaredNorm() > 0.0) || !normal.allFinite()) return;
    const auto id_a = body_a != nullptr ? static_cast<std::int32_t>(data_to_id(dGeomGetData(a))) : ContactGraph::kStatic;
    const auto id_b = body_b != nullptr ? static_cast<std::int32_t>(data_to_id(dGeomGetData(b))) : ContactGraph::kStatic;
    recorded.push_back({joint, id_a, id_b, normal, contact.surface.mu, speculative_contact});
  }

  // ODE's near callback: contact joints with the two materials combined. With speculative contacts a pair that is
  // still closing fast is given the contacts of where it will be (add_swept_contacts): it has only just met, and
  // ODE's contacts of a pair touching by a hair are any subset of its corners (two bottom corners of a face: a torque
  // that pitches both boxes).
  static void near_callback(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<Handles*>(data);
    if (dGeomGetBody(a) == nullptr && dGeomGetBody(b) == nullptr) return;  // static against static never moves
    dContact contacts[kMaxContactsPerPair];
    const int count = dCollide(a, b, kMaxContactsPerPair, &contacts[0].geom, sizeof(dContact));
    if (count == 0) return;
    const std::size_t id_a = data_to_id(dGeomGetData(a));
    const std::size_t id_b = data_to_id(dGeomGetData(b));
    if (self->speculative) {
      self->touching.push_back(pair_key(id_a, id_b));
      if (self->closing_fast(id_a, id_b, contacts[0].geom)) {
        self->closing.push_back({a, b});  // the body is moved for the test, which the locked space forbids here
        return;
      }
    }
    self->add_contacts(contacts, count, a, b);
  }

  void add_contacts(dContact* contacts, int count, dGeomID a, dGeomID b) {
    const std::size_t id_a = data_to_id(dGeomGetData(a));
    const std::size_t id_b = data_to_id(dGeomGetData(b));
    for (int i = 0; i < count; ++i) {
      set_surface(contacts[i].surface, materials[id_a], materials[id_b]);
      add_contact(contacts[i], a, b, false);
    }
  }

  // The pairs the near callback found closing fast, once the space is unlocked: the contacts of where they will be,
  // or their ordinary ones if the displacements part them.
  void add_closing_contacts() {
    for (const auto& [a, b] : closing) {
      if (add_swept_contacts(a, b)) continue;
      dContact contacts[kMaxContactsPerPair];
      add_contacts(contacts, dCollide(a, b, kMaxContactsPerPair, &contacts[0].geom, sizeof(dContact)), a, b);
    }
    closing.clear();
  }

  // Whether the pair's contact `touch` closes faster than a resting contact ever does (kBounceThreshold_mps, with the
  // velocities as they are, before this substep's gravity and forces).
  bool closing_fast(std::size_t id_a, std::size_t id_b, const dContactGeom& touch) const {
    const Eigen::Vector3d at(touch.pos[0], touch.pos[1], touch.pos[2]);
    const Eigen::Vector3d normal(touch.normal[0], touch.normal[1], touch.normal[2]);
    return -normal.dot(point_velocity(id_a, at) - point_velocity(id_b, at)) > kBounceThreshold_mps;
  }

  // The velocity of the point `at` on what carries geom `id` (zero for fixed geometry and the floor).
  Eigen::Vector3d point_velocity(std::size_t id, const Eigen::Vector3d& at) const {
    if (id >= bodies.size() || bodies[id] == nullptr) return Eigen::Vector3d::Zero();
    const dReal* p = dBodyGetPosition(bodies[id]);
    const dReal* v = dBodyGetLinearVel(bodies[id]);
    const dReal* w = dBodyGetAngularVel(bodies[id]);
    return Eigen::Vector3d(v[0], v[1], v[2]) +
           Eigen::Vector3d(w[0], w[1], w[2]).cross(at - Eigen::Vector3d(p[0], p[1], p[2]));
  }

  // The contacts the pair makes within this substep (speculative_contact.h), moving the one with a body (the lower id
  // if both have) by their relative free displacement; false if they do not meet. Where the pair is still apart by
  // gap the row lets it close the gap and no more (relative normal speed ≥ −gap/h; ERP adds nothing at zero depth);
  // a bouncing pair (restitution e, closing faster than the bounce threshold) leaves at e times its closing speed
  // from there, as ODE's bounce would one substep later from inside. Where it already overlaps, an ordinary contact.
  bool add_swept_contacts(dGeomID a, dGeomID b) {
    std::size_t id_a = data_to_id(dGeomGetData(a));
    std::size_t id_b = data_to_id(dGeomGetData(b));
    if (dGeomGetBody(a) == nullptr || (dGeomGetBody(b) != nullptr && id_b < id_a)) {
      std::swap(a, b);
      std::swap(id_a, id_b);
    }
    const Eigen::Vector3d relative_m = displacement_of(id_a) - displacement_of(id_b);
    if (!(relative_m.squaredNorm() > 0.0)) return false;
    dContact found[kMaxContactsPerPair];
    const int count = speculative_contacts(a, bodies[id_a], b, relative_m, found, kMaxContactsPerPair);
    for (int i = 0; i < count; ++i) {
      dContact& contact = found[i];
      set_surface(contact.surface, materials[id_a], materials[id_b]);
      const double gap_m = -contact.geom.depth;
      const bool apart = gap_m > 0.0;
      if (apart) {
        contact.geom.depth = 0.0;
        contact.surface.mode |= dContactMotionN;
        contact.surface.motionN = -gap_m / substep_s;
        if ((contact.surface.mode & dContactBounce) != 0) {
          contact.surface.mode &= ~dContactBounce;
          const Eigen::Vector3d at(contact.geom.pos[0], contact.geom.pos[1], contact.geom.pos[2]);
          const Eigen::Vector3d normal(contact.geom.normal[0], contact.geom.normal[1], contact.geom.normal[2]);
          const double closing_mps = -normal.dot(point_velocity(id_a, at) - point_velocity(id_b, at));
          if (closing_mps > contact.surface.bounce_vel) contact.surface.motionN = contact.surface.bounce * closing_mps;
        }
      }
      add_contact(contact, a, b, apart);
    }
    return count > 0;
  }

  // The displacement body `id` makes in a substep of h if nothing touches it: semi-implicit Euler, as ODE steps,
  // with gravity and the forces applied so far (the couplings add theirs before the substep).
  Eigen::Vector3d free_displacement(std::size_t id, double h) const {
    dBodyID body = bodies[id];
    dMass mass;
    dBodyGetMass(body, &mass);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* f = dBodyGetForce(body);
    Eigen::Vector3d acceleration = Eigen::Vector3d(f[0], f[1], f[2]) / mass.mass;
    if (dBodyGetGravityMode(body) != 0) acceleration += Eigen::Vector3d(scene->gravity_mps2.data());
    return h * (Eigen::Vector3d(v[0], v[1], v[2]) + h * acceleration);
  }

  // Every moving body's free displacement for the coming substep.
  void predict_displacements(double h) {
    auto predict = [&](std::size_t id) {
      if (bodies[id] == nullptr || escape_guard.escaped(id) || dBodyIsEnabled(bodies[id]) == 0) return;
      displacement[id] = free_displacement(id, h);
    };
    if (sleeping) {
      for (const std::size_t id : awake) predict(id);
    } else {
      for (std::size_t id = 0; id < bodies.size(); ++id) predict(id);
    }
  }

  // The displacement of whatever carries geom `id` this substep: zero for fixed geometry, the floor and sleepers.
  Eigen::Vector3d displacement_of(std::size_t id) const {
    if (id >= bodies.size() || bodies[id] == nullptr || escape_guard.escaped(id) || dBodyIsEnabled(bodies[id]) == 0) {
      return Eigen::Vector3d::Zero();
    }
    return displacement[id];
  }

  // The bounds `id`'s geom sweeps in the substep.
  Eigen::AlignedBox3d swept_bounds(std::size_t id) const {
    Eigen::AlignedBox3d bounds = geom_bounds(geoms[id]);
    Eigen::AlignedBox3d moved_bounds = bounds;
    return bounds.extend(moved_bounds.translate(displacement[id]));
  }

  // Speculative contacts (speculative_contact.h) of every moving body with what it would reach in this substep and
  // does not touch yet. Moving pairs by sweep and prune over their swept bounds along x (O(n log n) in the bodies
  // that move); fixed geometry from the grid (with sleeping) or the list of it, and the floor.
  void speculate() {
    std::sort(touching.begin(), touching.end());
    sweeps.clear();
    auto add_sweep = [&](std::size_t id) {
      if (bodies[id] == nullptr || escape_guard.escaped(id) || dBodyIsEnabled(bodies[id]) == 0) return;
      sweeps.push_back({id, swept_bounds(id)});
    };
    if (sleeping) {
      for (const std::size_t id : awake) add_sweep(id);
    } else {
      for (std::size_t id = 0; id < bodies.size(); ++id) add_sweep(id);
    }
    std::sort(sweeps.begin(), sweeps.end(),
              [](const Sweep& a, const Sweep& b) { return a.bounds.min().x() < b.bounds.min().x(); });
    for (std::size_t i = 0; i < sweeps.size(); ++i) {
      const Sweep& a = sweeps[i];
      for (std::size_t j = i + 1; j < sweeps.size() && sweeps[j].bounds.min().x() <= a.bounds.max().x(); ++j) {
        if (!a.bounds.intersects(sweeps[j].bounds)) continue;
        const std::size_t low = std::min(a.id, sweeps[j].id), high = std::max(a.id, sweeps[j].id);
        speculate_pair(low, geoms[high]);
      }
      if (floor != nullptr) speculate_pair(a.id, floor);
      if (sleeping) {
        grid->query(a.bounds, nearby);
        for (const std::int32_t other : nearby) {
          const auto o = static_cast<std::size_t>(other);
          if (kind[o] == Kind::fixed && a.bounds.intersects(resting_bounds[o])) speculate_pair(a.id, geoms[o]);
        }
      } else {
        for (const auto& [o, bounds] : fixed_bounds) {
          if (a.bounds.intersects(bounds)) speculate_pair(a.id, geoms[o]);
        }
      }
    }
  }

  // Body `id` against `other` (fixed, the floor, or a body of higher id), unless they touch already.
  void speculate_pair(std::size_t id, dGeomID other) {
    if (dGeomIsEnabled(other) == 0) return;
    const std::size_t other_id = data_to_id(dGeomGetData(other));
    if (std::binary_search(touching.begin(), touching.end(), pair_key(id, other_id))) return;
    add_swept_contacts(geoms[id], other);
  }
};

OdeEngine::OdeEngine(const Scene& scene) : ode_(std::make_unique<Handles>()) {
  Handles& ode = *ode_;
  ode.scene = &scene;
  ode.world = dWorldCreate();
  ode.sleeping = scene.physics.auto_disable;
  // ODE's hash space keeps an n×n bit matrix of the pairs it has tested, cleared at every collide: 1.25 GB per substep
  // at 100 k geoms (12.5 MB at 10 k). With sleeping every body is awake at the start, so the awake space sweeps and
  // prunes instead (sorted along x, then y: scenes spread over a floor), O(n log n). Without sleeping the hash space
  // stays, whose contact order the published figures were made with.
  ode.space = ode.sleeping ? dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ) : dHashSpaceCreate(nullptr);
  if (ode.sleeping) ode.resting_space = dSimpleSpaceCreate(nullptr);  // never collided as a whole: it only owns
  ode.contacts = dJointGroupCreate(0);
  ode.speculative = scene.physics.speculative_contacts;
  if (ode.speculative) {
    ode.displacement.assign(scene.objects.size(), Eigen::Vector3d::Zero());
  }
  dWorldSetGravity(ode.world, scene.gravity_mps2[0], scene.gravity_mps2[1], scene.gravity_mps2[2]);
  if (std::isfinite(scene.physics.ode.max_correcting_velocity_mps)) {
    dWorldSetContactMaxCorrectingVel(ode.world, scene.physics.ode.max_correcting_velocity_mps);
  }
  dWorldSetQuickStepNumIterations(ode.world, scene.physics.ode.solver_iterations);
  dWorldSetAutoDisableFlag(ode.world, scene.physics.auto_disable ? 1 : 0);
  if (ode.sleeping) {
    dWorldSetAutoDisableLinearThreshold(ode.world, kSleepSpeed_mps);
    dWorldSetAutoDisableAngularThreshold(ode.world, kSleepAngularSpeed_radps);
    dWorldSetAutoDisableSteps(ode.world, 0);
    dWorldSetAutoDisableTime(ode.world, kRestBeforeSleep_s);
  }

  ode.bodies.assign(scene.objects.size(), nullptr);
  ode.contact_graph.reset(scene.objects.size());
  ode.geoms.assign(scene.objects.size(), nullptr);
  ode.escape_guard = EscapeGuard(scene.objects.size());
  ode.inverse_inertia_body.assign(scene.objects.size(), Eigen::Matrix3d::Zero());
  if (ode.sleeping) {
    ode.kind.assign(scene.objects.size(), Handles::Kind::fixed);
    ode.masses.resize(scene.objects.size());
    ode.resting_pose.resize(scene.objects.size());
    ode.resting_bounds.resize(scene.objects.size());
    ode.grid = std::make_unique<SpatialGrid>(grid_cell_size_m(scene));
    ode.grid->reset(scene.objects.size());
  }
  for (std::size_t id = 0; id < scene.objects.size(); ++id) {
    const SceneObject& object = scene.objects[id];
    const Shape& shape = object.shape;
    dGeomID geom = nullptr;
    dMass mass;
    dMassSetZero(&mass);
    constexpr int kAxisZ = 3;  // ODE's direction code for the body z axis
    // With sleeping, fixed geometry is never collided as a whole, only looked up in the grid around awake bodies.
    dSpaceID home = ode.sleeping && !object.dynamic ? ode.resting_space : ode.space;
    switch (shape.kind) {
      case ShapeKind::box:
        geom = dCreateBox(home, shape.box_size_m[0], shape.box_size_m[1], shape.box_size_m[2]);
        if (object.dynamic) {
          dMassSetBoxTotal(&mass, object.mass_kg, shape.box_size_m[0], shape.box_size_m[1], shape.box_size_m[2]);
        }
        break;
      case ShapeKind::sphere:
        geom = dCreateSphere(home, shape.radius_m);
        if (object.dynamic) dMassSetSphereTotal(&mass, object.mass_kg, shape.radius_m);
        break;
      case ShapeKind::capsule:
        geom = dCreateCapsule(home, shape.radius_m, shape.length_m);
        if (object.dynamic) dMassSetCapsuleTotal(&mass, object.mass_kg, kAxisZ, shape.radius_m, shape.length_m);
        break;
      case ShapeKind::cylinder:
        geom = dCreateCylinder(home, shape.radius_m, shape.length_m);
        if (object.dynamic) dMassSetCylinderTotal(&mass, object.mass_kg, kAxisZ, shape.radius_m, shape.length_m);
        break;
      case ShapeKind::none:
        throw SceneError("object '" + object.name + "' has no shape");
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
      ode.inverse_inertia_body[id] = ode_inertia(mass).inverse();
      ode.moved.push_back(id);
      if (ode.sleeping) {
        ode.kind[id] = Handles::Kind::awake;
        ode.masses[id] = mass;
        ode.awake.push_back(id);
      }
    } else {
      dGeomSetPosition(geom, object.position_m[0], object.position_m[1], object.position_m[2]);
      dGeomSetQuaternion(geom, orientation);
      if (ode.sleeping) {
        ode.resting_bounds[id] = geom_bounds(geom);
        ode.grid->update(static_cast<std::int32_t>(id), ode.resting_bounds[id]);
      } else if (ode.speculative) {
        ode.fixed_bounds.emplace_back(id, geom_bounds(geom));
      }
    }
    ode.materials.push_back(object.material);
  }
  ode.materials.push_back(scene.floor.material);
  if (scene.floor.present) {
    dGeomID floor = dCreatePlane(ode.sleeping ? ode.resting_space : ode.space, 0.0, 0.0, 1.0, scene.floor.height_m);
    dGeomSetData(floor, id_to_data(scene.objects.size()));
    ode.floor = floor;
  }

  dRandSetSeed(static_cast<unsigned long>(scene.physics.seed));
  ode.random_state = dRandGetSeed();
}

OdeEngine::~OdeEngine() = default;

void OdeEngine::read_state(std::size_t id, ObjectState& out) const {
  if (asleep(id)) {
    const Handles::RestingPose& pose = ode_->resting_pose[id];
    out.pose.position_m = Eigen::Vector3d(pose.position[0], pose.position[1], pose.position[2]);
    out.pose.orientation = Eigen::Quaterniond(pose.orientation[0], pose.orientation[1], pose.orientation[2],
                                              pose.orientation[3]);
    out.velocity_mps.setZero();
    out.angular_velocity_radps.setZero();
    return;
  }
  dBodyID body = ode_->bodies[id];
  const dReal* position = dBodyGetPosition(body);
  const dReal* q = dBodyGetQuaternion(body);
  const dReal* velocity = dBodyGetLinearVel(body);
  const dReal* angular = dBodyGetAngularVel(body);
  out.pose.position_m = Eigen::Vector3d(position[0], position[1], position[2]);
  out.pose.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  out.velocity_mps = Eigen::Vector3d(velocity[0], velocity[1], velocity[2]);
  out.angular_velocity_radps = Eigen::Vector3d(angular[0], angular[1], angular[2]);
}

const Eigen::Matrix3d& OdeEngine::inverse_inertia_body(std::size_t id) const { return ode_->inverse_inertia_body[id]; }

void OdeEngine::velocity(std::size_t id, Eigen::Vector3d& velocity_mps, Eigen::Vector3d& angular_radps) const {
  if (asleep(id)) {
    velocity_mps.setZero();
    angular_radps.setZero();
    return;
  }
  const dReal* v = dBodyGetLinearVel(ode_->bodies[id]);
  const dReal* w = dBodyGetAngularVel(ode_->bodies[id]);
  velocity_mps = Eigen::Vector3d(v[0], v[1], v[2]);
  angular_radps = Eigen::Vector3d(w[0], w[1], w[2]);
}

void OdeEngine::set_velocity(std::size_t id, const Eigen::Vector3d& velocity_mps,
                             const Eigen::Vector3d& angular_radps) {
  if (ode_->sleeping) wake(id);
  dBodyID body = ode_->bodies[id];
  dBodySetLinearVel(body, velocity_mps.x(), velocity_mps.y(), velocity_mps.z());
  dBodySetAngularVel(body, angular_radps.x(), angular_radps.y(), angular_radps.z());
}

void OdeEngine::wake(std::size_t id) {
  if (asleep(id)) ode_->wake_up(id);
  dBodyEnable(ode_->bodies[id]);  // also restarts ODE's count of the time the body has rested
}

bool OdeEngine::asleep(std::size_t id) const {
  return ode_->sleeping && ode_->kind[id] == Handles::Kind::asleep;
}

void OdeEngine::add_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) {
  if (ode_->sleeping) wake(id);
  dBodyID body = ode_->bodies[id];
  dBodyAddForce(body, force_N.x(), force_N.y(), force_N.z());
  dBodyAddTorque(body, torque_Nm.x(), torque_Nm.y(), torque_Nm.z());
}

void OdeEngine::add_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m) {
  if (ode_->sleeping) wake(id);
  dBodyAddForceAtPos(ode_->bodies[id], force_N.x(), force_N.y(), force_N.z(), point_m.x(), point_m.y(), point_m.z());
}

void OdeEngine::step(int substeps, double substep_s, bool record_contacts, SubstepHook& hook) {
  Handles& ode = *ode_;
  const Scene& scene = *ode.scene;
  dRandSetSeed(ode.random_state);
  // The contact's spring and damper as ODE's numbers for this substep (scene.h PhysicsParams).
  dWorldSetERP(ode.world, scene.physics.erp_at(substep_s));
  dWorldSetCFM(ode.world, scene.physics.cfm_at(substep_s));
  if (ode.sleeping) {
    ode.moved.assign(ode.awake.begin(), ode.awake.end());
    std::sort(ode.moved.begin(), ode.moved.end());
  }
  for (int substep = 0; substep < substeps; ++substep) {
    hook.before_substep(substep);
    ode.record_contacts = record_contacts && substep + 1 == substeps;
    const bool recording = ode.record_contacts;
    if (recording) ode.recorded.clear();
    ode.park_escaped();
    ode.touching.clear();
    ode.substep_s = substep_s;
    if (ode.sleeping) ode.wake_touched(substep_s);
    if (ode.speculative) ode.predict_displacements(substep_s);
    if (ode.sleeping) {
      ode.collide_awake();
    } else {
      dSpaceCollide(ode.space, &ode, &Handles::near_callback);
    }
    if (ode.speculative) {
      ode.add_closing_contacts();
      ode.speculate();
    }
    ode.record_contacts = false;
    if (recording) {
      ode.feedback.resize(ode.recorded.size());
      for (std::size_t c = 0; c < ode.recorded.size(); ++c) dJointSetFeedback(ode.recorded[c].joint, &ode.feedback[c]);
    }
    if (scene.physics.ode.solver == OdeParams::Solver::direct) {
      dWorldStep(ode.world, substep_s);
    } else {
      dWorldQuickStep(ode.world, substep_s);
    }
    if (recording) ode.record_graph();
    dJointGroupEmpty(ode.contacts);
  }
  ode.park_escaped();  // the world reads the state next
  if (ode.sleeping) ode.put_rested_to_sleep();
  ode.random_state = dRandGetSeed();
}

const std::vector<std::size_t>& OdeEngine::moved() const { return ode_->moved; }

ContactGraph& OdeEngine::contacts() { return ode_->contact_graph; }

const std::vector<std::size_t>& OdeEngine::escaped() const { return ode_->escape_guard.escaped(); }

}  // namespace impetus
