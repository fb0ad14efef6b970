// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/ode_engine.h"

#include "world_manager/engine/ball_mesh_contacts.h"
#include "world_manager/engine/escape_guard.h"
#include "world_manager/engine/sleeping_bodies.h"
#include "world_manager/engine/smooth_floor.h"
#include "world_manager/engine/speculative_contacts.h"

#include "common/mesh/mesh_body.h"

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace impetus {
namespace {

Eigen::AlignedBox3d geom_bounds(dGeomID geom) {
  dReal aabb[6];
  dGeomGetAABB(geom, aabb);  // ODE's order: min x, max x, min y, max y, min z, max z
  return Eigen::AlignedBox3d(Eigen::Vector3d(aabb[0], aabb[2], aabb[4]), Eigen::Vector3d(aabb[1], aabb[3], aabb[5]));
}

// The median object extent: a sleeping grid's cell then holds a few objects and an object spans a few cells.
double grid_cell_size_m(const Scene& scene) {
  std::vector<double> extents_m;
  for (const SceneObject& object : scene.objects) extents_m.push_back(largest_extent_m(object.shape));
  if (extents_m.empty()) return 1.0;
  auto middle = extents_m.begin() + static_cast<std::ptrdiff_t>(extents_m.size() / 2);
  std::nth_element(extents_m.begin(), middle, extents_m.end());
  return *middle;
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

struct OdeEngine::Handles final : EscapeGuard::Engine, SleepingBodies::Engine, SpeculativeContacts::Engine {
  using Point = SpeculativeContacts::Point;

  const Scene* scene = nullptr;
  dWorldID world = nullptr;
  dSpaceID space = nullptr;  // with sleeping: the awake geoms only
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> bodies;      // per object; nullptr for static objects and sleeping bodies
  std::vector<dGeomID> geoms;       // per object
  std::vector<Material> materials;  // per id, the floor last
  std::vector<Eigen::Matrix3d> inverse_inertia_body;  // per object; zero for static ones
  std::vector<std::size_t> dynamic_ids;               // ascending
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

  // The engine-neutral services over this engine; each absent when the scene turns it off.
  std::unique_ptr<SleepingBodies> sleeping;          // physics.auto_disable
  std::unique_ptr<SpeculativeContacts> speculative;  // physics.speculative_contacts
  dSpaceID resting_space = nullptr;  // with sleeping: owns the geoms of static objects, sleeping bodies and the floor
  dGeomID floor = nullptr;           // in resting_space with sleeping, else in space
  struct RestingPose {
    dVector3 position;
    dQuaternion orientation;
  };
  std::vector<RestingPose> resting_pose;  // per object, while it sleeps
  std::vector<dMass> masses;              // per object, to rebuild a body that wakes
  std::vector<std::size_t> nearby;        // scratch
  std::vector<dTriMeshDataID> mesh_data;  // one per mesh geom; ODE reads the MeshBody's arrays, it copies nothing
  std::vector<std::unique_ptr<SmoothFloor>> smooth_floor;  // per object: a smooth mesh's touches of the floor, or null
  std::vector<const MeshBody*> mesh_bodies;                 // per object: a mesh object's triangles, or null
  // Dented tops (dent_top), per object: the heightfield geom beside the object's box (nullptr: none), the grid it
  // reads (its address is ODE's user data, so the vector is sized once) and ODE's data for it.
  std::vector<dGeomID> tops;
  std::vector<DentedTop> top_grids;
  std::vector<dHeightfieldDataID> top_data;

  dGeomID geom_of(std::size_t id) const { return id < geoms.size() ? geoms[id] : floor; }

  // The bodies whose motion the services look at: the awake ones with sleeping, else every dynamic one.
  const std::vector<std::size_t>& movers() const { return sleeping ? sleeping->awake() : dynamic_ids; }

  // SleepingBodies::Engine
  Eigen::AlignedBox3d bounds(std::size_t id) const override { return geom_bounds(geom_of(id)); }
  Eigen::AlignedBox3d reach_bounds(std::size_t id, double substep_s) override {
    Eigen::AlignedBox3d reach = bounds(id);
    if (speculative) {
      speculative->remember(id, speculative->free_displacement(id, substep_s, *this));
      reach = speculative->swept_bounds(id, *this);
    }
    return reach;
  }
  bool reaches(std::size_t id, std::size_t other) override {
    dContactGeom touch;
    if (collide(geoms[id], geoms[other], 1, &touch, sizeof(dContactGeom)) > 0) return true;
    return speculative && speculative->meets(id, other, *this);
  }
  bool rested(std::size_t id) const override { return dBodyIsEnabled(bodies[id]) == 0; }
  void leave_solver(std::size_t id) override {
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
  }
  void enter_solver(std::size_t id) override {
    dGeomID geom = geoms[id];
    const RestingPose& pose = resting_pose[id];
    dBodyID body = dBodyCreate(world);
    dBodySetMass(body, &masses[id]);
    dBodySetPosition(body, pose.position[0], pose.position[1], pose.position[2]);
    dBodySetQuaternion(body, pose.orientation);
    dGeomSetBody(geom, body);
    bodies[id] = body;
    dSpaceRemove(resting_space, geom);
    dSpaceAdd(space, geom);
  }

  // SpeculativeContacts::Engine
  std::optional<SpeculativeContacts::Motion> motion(std::size_t id) const override {
    dBodyID body = bodies[id];
    if (body == nullptr) return std::nullopt;
    dMass mass;
    dBodyGetMass(body, &mass);
    const dReal* p = dBodyGetPosition(body);
    const dReal* v = dBodyGetLinearVel(body);
    const dReal* w = dBodyGetAngularVel(body);
    const dReal* f = dBodyGetForce(body);
    return SpeculativeContacts::Motion{Eigen::Vector3d(p[0], p[1], p[2]), Eigen::Vector3d(v[0], v[1], v[2]),
                                       Eigen::Vector3d(w[0], w[1], w[2]), Eigen::Vector3d(f[0], f[1], f[2]),
                                       mass.mass, dBodyGetGravityMode(body) != 0, dBodyIsEnabled(body) == 0};
  }
  int collide_displaced(std::size_t id, std::size_t other, const Eigen::Vector3d& displacement_m,
                        Point* out) override {
    dBodyID body = bodies[id];
    const dReal* p = dBodyGetPosition(body);
    const dReal start[3] = {p[0], p[1], p[2]};
    dBodySetPosition(body, start[0] + displacement_m.x(), start[1] + displacement_m.y(), start[2] + displacement_m.z());
    dContactGeom found[kMaxContactsPerPair];
    const int count = collide(geoms[id], geom_of(other), kMaxContactsPerPair, found, sizeof(dContactGeom));
    dBodySetPosition(body, start[0], start[1], start[2]);
    for (int i = 0; i < count; ++i) out[i] = point_of(found[i]);
    return count;
  }
  void add_row(std::size_t a, std::size_t b, const SpeculativeContacts::Row& row) override {
    dContact contact{};
    contact.geom.g1 = geoms[a];
    contact.geom.g2 = geom_of(b);
    for (int k = 0; k < 3; ++k) {
      contact.geom.pos[k] = row.point.position_m[k];
      contact.geom.normal[k] = row.point.normal[k];
    }
    contact.geom.depth = row.point.depth_m;
    set_surface(contact.surface, materials[a], materials[b]);
    if (row.speculative) {
      contact.surface.mode |= dContactMotionN;
      contact.surface.mode &= ~dContactBounce;
      contact.surface.motionN = row.normal_speed_mps;
    }
    add_contact(contact, geoms[a], geom_of(b), row.speculative);
  }
  void add_ordinary_contacts(std::size_t a, std::size_t b) override {
    dGeomID ga = geom_of(a);
    dGeomID gb = geom_of(b);
    dContact found[kMaxContactsPerPair];
    add_contacts(found, collide(ga, gb, kMaxContactsPerPair, &found[0].geom, sizeof(dContact)), ga, gb);
  }

  // ODE's contacts of two geoms (dCollide), but a smooth mesh touches the floor with its smooth surface
  // (smooth_floor.h): the facets' contacts are where to look from, and the surface's replace them.
  int collide(dGeomID a, dGeomID b, int max, dContactGeom* out, int stride) {
    if (const int on_mesh = ball_on_mesh(a, b, max, out, stride); on_mesh >= 0) return on_mesh;
    const int count = dCollide(a, b, max, out, stride);
    if (floor == nullptr || (a != floor && b != floor)) return count;
    const dGeomID mesh = a == floor ? b : a;
    const std::size_t id = data_to_id(dGeomGetData(mesh));
    if (id >= smooth_floor.size() || smooth_floor[id] == nullptr) return count;
    // Far above the floor (farther than the surface ever lies below the facets' box): nothing to climb for.
    dReal box[6];
    dGeomGetAABB(mesh, box);
    if (box[4] > scene->floor.height_m + smooth_floor[id]->reach_m()) return count;
    const auto at = [&](int i) {
      return reinterpret_cast<dContactGeom*>(reinterpret_cast<char*>(out) + static_cast<std::ptrdiff_t>(i) * stride);
    };
    std::array<Eigen::Vector3d, kMaxContactsPerPair> facets;
    const int facet_count = std::min(count, kMaxContactsPerPair);
    for (int i = 0; i < facet_count; ++i) facets[i] = Eigen::Vector3d(at(i)->pos[0], at(i)->pos[1], at(i)->pos[2]);
    const dReal* p = dGeomGetPosition(mesh);
    const dReal* r = dGeomGetRotation(mesh);  // 3×4, row-major
    Eigen::Matrix3d rotation;
    rotation << r[0], r[1], r[2], r[4], r[5], r[6], r[8], r[9], r[10];
    std::array<FloorTouch, kMaxContactsPerPair> touches;
    const int touch_count = smooth_floor[id]->touches(
        Eigen::Vector3d(p[0], p[1], p[2]), rotation, scene->floor.height_m,
        std::span<const Eigen::Vector3d>(facets.data(), static_cast<std::size_t>(facet_count)),
        std::span<FloorTouch>(touches.data(), static_cast<std::size_t>(std::min(max, kMaxContactsPerPair))));
    if (touch_count == SmoothFloor::kUseFacets) return count;
    const double up = a == mesh ? 1.0 : -1.0;  // ODE's normal points into geom 1: the floor pushes the mesh up
    for (int i = 0; i < touch_count; ++i) {
      dContactGeom& contact = *at(i);
      for (int k = 0; k < 3; ++k) contact.pos[k] = touches[static_cast<std::size_t>(i)].point_m[k];
      contact.pos[3] = 0.0;
      contact.normal[0] = 0.0;
      contact.normal[1] = 0.0;
      contact.normal[2] = up;
      contact.normal[3] = 0.0;
      contact.depth = touches[static_cast<std::size_t>(i)].depth_m;
      contact.g1 = a;
      contact.g2 = b;
      contact.side1 = -1;
      contact.side2 = -1;
    }
    return touch_count;
  }

  // A ball against a mesh object: the contacts from the mesh's own tree (ball_mesh_contacts.h), which hold a ball on
  // triangles of any size, where ODE's sphere–trimesh test lets it through small ones. −1: not such a pair.
  int ball_on_mesh(dGeomID a, dGeomID b, int max, dContactGeom* out, int stride) {
    const bool a_ball = dGeomGetClass(a) == dSphereClass;
    if (a_ball == (dGeomGetClass(b) == dSphereClass)) return -1;
    const dGeomID ball = a_ball ? a : b;
    const dGeomID mesh = a_ball ? b : a;
    if (dGeomGetClass(mesh) != dTriMeshClass) return -1;
    const std::size_t id = data_to_id(dGeomGetData(mesh));
    if (id >= mesh_bodies.size() || mesh_bodies[id] == nullptr) return -1;
    const dReal* centre = dGeomGetPosition(ball);
    const dReal* p = dGeomGetPosition(mesh);
    const dReal* r = dGeomGetRotation(mesh);  // 3×4, row-major
    Eigen::Matrix3d rotation;
    rotation << r[0], r[1], r[2], r[4], r[5], r[6], r[8], r[9], r[10];
    std::array<BallContact, kMaxContactsPerPair> contacts;
    const int count = ball_mesh_contacts(
        Eigen::Vector3d(centre[0], centre[1], centre[2]), dGeomSphereGetRadius(ball), *mesh_bodies[id],
        Eigen::Vector3d(p[0], p[1], p[2]), rotation,
        std::span<BallContact>(contacts.data(), static_cast<std::size_t>(std::min(max, kMaxContactsPerPair))));
    const double sign = a_ball ? 1.0 : -1.0;  // ODE's normal points into geom 1: the mesh pushes the ball out
    for (int i = 0; i < count; ++i) {
      const BallContact& found = contacts[static_cast<std::size_t>(i)];
      auto* contact =
          reinterpret_cast<dContactGeom*>(reinterpret_cast<char*>(out) + static_cast<std::ptrdiff_t>(i) * stride);
      for (int k = 0; k < 3; ++k) {
        contact->pos[k] = found.point_m[k];
        contact->normal[k] = sign * found.normal[k];
      }
      contact->pos[3] = 0.0;
      contact->normal[3] = 0.0;
      contact->depth = found.depth_m;
      contact->g1 = a;
      contact->g2 = b;
      contact->side1 = -1;
      contact->side2 = -1;
    }
    return count;
  }

  static Point point_of(const dContactGeom& geom) {
    return Point{Eigen::Vector3d(geom.pos[0], geom.pos[1], geom.pos[2]),
                 Eigen::Vector3d(geom.normal[0], geom.normal[1], geom.normal[2]), geom.depth};
  }

  // Contacts of the awake geoms: among themselves (the space), with the floor and with fixed geometry (the grid).
  // Sleeping bodies an awake one touches were woken first (SleepingBodies::wake_touched), so none is met here.
  void collide_awake() {
    dSpaceCollide(space, this, &Handles::near_callback);
    for (const std::size_t id : sleeping->awake()) {
      if (escape_guard.escaped(id)) continue;
      dGeomID geom = geoms[id];
      if (floor != nullptr) near_callback(this, geom, floor);
      sleeping->fixed_near(geom_bounds(geom), nearby);
      for (const std::size_t o : nearby) {
        near_callback(this, geom, geoms[o]);
        if (tops[o] != nullptr) near_callback(this, geom, tops[o]);
      }
    }
  }

  // Takes every body the solver has thrown out of range out of the simulation before the broadphase sees it (ODE's
  // hash space asserts on coordinates it cannot store in its cells): escape_guard.h decides, park() does.
  void park_escaped() {
    if (sleeping) {
      escape_guard.check(sleeping->awake(), *this);
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

  ~Handles() override {
    if (contacts != nullptr) dJointGroupDestroy(contacts);
    if (resting_space != nullptr) dSpaceDestroy(resting_space);
    if (space != nullptr) dSpaceDestroy(space);  // destroys the geoms it holds (cleanup mode on)
    if (world != nullptr) dWorldDestroy(world);  // destroys the bodies
    for (dTriMeshDataID data : mesh_data) dGeomTriMeshDataDestroy(data);  // after the geoms that use it
    for (dHeightfieldDataID data : top_data) dGeomHeightfieldDataDestroy(data);
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

  // ODE's near callback: contact joints with the two materials combined. With speculative contacts a pair still
  // closing fast is left to the service (SpeculativeContacts::defer_touching): the body is moved for its test, which
  // the locked space forbids here.
  static void near_callback(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<Handles*>(data);
    if (dGeomGetBody(a) == nullptr && dGeomGetBody(b) == nullptr) return;  // static against static never moves
    dContact found[kMaxContactsPerPair];
    const int count = self->collide(a, b, kMaxContactsPerPair, &found[0].geom, sizeof(dContact));
    if (count == 0) return;
    if (self->speculative &&
        self->speculative->defer_touching(data_to_id(dGeomGetData(a)), data_to_id(dGeomGetData(b)),
                                          point_of(found[0].geom), *self)) {
      return;
    }
    self->add_contacts(found, count, a, b);
  }

  void add_contacts(dContact* found, int count, dGeomID a, dGeomID b) {
    const std::size_t id_a = data_to_id(dGeomGetData(a));
    const std::size_t id_b = data_to_id(dGeomGetData(b));
    for (int i = 0; i < count; ++i) {
      set_surface(found[i].surface, materials[id_a], materials[id_b]);
      add_contact(found[i], a, b, false);
    }
  }
};

OdeEngine::OdeEngine(const Scene& scene) : ode_(std::make_unique<Handles>()) {
  Handles& ode = *ode_;
  ode.scene = &scene;
  ode.world = dWorldCreate();
  const bool sleeping = scene.physics.auto_disable;
  // ODE's hash space keeps an n×n bit matrix of the pairs it has tested, cleared at every collide: 1.25 GB per substep
  // at 100 k geoms (12.5 MB at 10 k). With sleeping every body is awake at the start, so the awake space sweeps and
  // prunes instead (sorted along x, then y: scenes spread over a floor), O(n log n). Without sleeping the hash space
  // stays, whose contact order the published figures were made with.
  ode.space = sleeping ? dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ) : dHashSpaceCreate(nullptr);
  if (sleeping) ode.resting_space = dSimpleSpaceCreate(nullptr);  // never collided as a whole: it only owns
  ode.contacts = dJointGroupCreate(0);
  dWorldSetGravity(ode.world, scene.gravity_mps2[0], scene.gravity_mps2[1], scene.gravity_mps2[2]);
  if (std::isfinite(scene.physics.ode.max_correcting_velocity_mps)) {
    dWorldSetContactMaxCorrectingVel(ode.world, scene.physics.ode.max_correcting_velocity_mps);
  }
  dWorldSetQuickStepNumIterations(ode.world, scene.physics.ode.solver_iterations);
  // The rest rule (sleeping_bodies.h) as ODE's auto-disable: it stops a body whose speeds stayed under the thresholds
  // for the rest time (and wakes one an enabled body touches); SleepingBodies then takes it out of ODE.
  dWorldSetAutoDisableFlag(ode.world, sleeping ? 1 : 0);
  if (sleeping) {
    dWorldSetAutoDisableLinearThreshold(ode.world, SleepingBodies::kSleepSpeed_mps);
    dWorldSetAutoDisableAngularThreshold(ode.world, SleepingBodies::kSleepAngularSpeed_radps);
    dWorldSetAutoDisableSteps(ode.world, 0);
    dWorldSetAutoDisableTime(ode.world, SleepingBodies::kRestBeforeSleep_s);
  }

  const std::size_t count = scene.objects.size();
  ode.bodies.assign(count, nullptr);
  ode.contact_graph.reset(count);
  ode.geoms.assign(count, nullptr);
  ode.tops.assign(count, nullptr);
  ode.top_grids.assign(count, DentedTop{});
  ode.escape_guard = EscapeGuard(count);
  ode.inverse_inertia_body.assign(count, Eigen::Matrix3d::Zero());
  for (const SceneObject& object : scene.objects) ode.materials.push_back(object.material);
  ode.materials.push_back(scene.floor.material);
  if (sleeping) {
    ode.masses.resize(count);
    ode.resting_pose.resize(count);
    ode.sleeping = std::make_unique<SleepingBodies>(count, grid_cell_size_m(scene), ode.escape_guard, ode.contact_graph);
  }
  if (scene.physics.speculative_contacts) {
    ode.speculative = std::make_unique<SpeculativeContacts>(count, scene.floor.present,
                                                            Eigen::Vector3d(scene.gravity_mps2.data()), ode.materials,
                                                            ode.escape_guard, ode.sleeping.get());
  }
  for (std::size_t id = 0; id < count; ++id) {
    const SceneObject& object = scene.objects[id];
    const Shape& shape = object.shape;
    dGeomID geom = nullptr;
    dMass mass;
    dMassSetZero(&mass);
    constexpr int kAxisZ = 3;  // ODE's direction code for the body z axis
    // With sleeping, fixed geometry is never collided as a whole, only looked up in the grid around awake bodies.
    dSpaceID home = sleeping && !object.dynamic ? ode.resting_space : ode.space;
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
      case ShapeKind::mesh: {
        const auto* body = dynamic_cast<const MeshBody*>(find_mesh_geometry(shape.mesh_hash));
        if (body == nullptr) throw SceneError("object '" + object.name + "': its mesh was not loaded");
        const TriangleMesh& mesh = body->bvh().mesh();
        static_assert(sizeof(dTriIndex) == sizeof(std::uint32_t));
        dTriMeshDataID data = dGeomTriMeshDataCreate();
        dGeomTriMeshDataBuildDouble(data, mesh.vertices_m.data(), sizeof(Eigen::Vector3d),
                                    static_cast<int>(mesh.vertices_m.size()), mesh.triangles.data(),
                                    static_cast<int>(3 * mesh.triangles.size()), sizeof(mesh.triangles[0]));
        ode.mesh_data.push_back(data);
        geom = dCreateTriMesh(home, data, nullptr, nullptr, nullptr);
        ode.mesh_bodies.resize(scene.objects.size(), nullptr);
        ode.mesh_bodies[id] = body;
        if (object.smooth_surface) {
          ode.smooth_floor.resize(scene.objects.size());
          ode.smooth_floor[id] = std::make_unique<SmoothFloor>(*body);
        }
        if (object.dynamic) {
          const Eigen::Matrix3d inertia = object.mass_kg * body->inertia_per_kg();
          dMassSetParameters(&mass, object.mass_kg, 0.0, 0.0, 0.0, inertia(0, 0), inertia(1, 1), inertia(2, 2),
                             inertia(0, 1), inertia(0, 2), inertia(1, 2));
        }
        break;
      }
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
      ode.dynamic_ids.push_back(id);
      if (sleeping) {
        ode.masses[id] = mass;
        ode.sleeping->add_awake(id);
      }
    } else {
      dGeomSetPosition(geom, object.position_m[0], object.position_m[1], object.position_m[2]);
      dGeomSetQuaternion(geom, orientation);
      if (sleeping) {
        ode.sleeping->add_fixed(id, geom_bounds(geom));
      } else if (ode.speculative) {
        ode.speculative->add_fixed(id, geom_bounds(geom));
      }
    }
  }
  if (scene.floor.present) {
    dGeomID floor = dCreatePlane(sleeping ? ode.resting_space : ode.space, 0.0, 0.0, 1.0, scene.floor.height_m);
    dGeomSetData(floor, id_to_data(count));
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
  if (asleep(id)) ode_->sleeping->wake(id, *ode_);
  dBodyEnable(ode_->bodies[id]);  // also restarts ODE's count of the time the body has rested
}

namespace {

// ODE's heightfield lies in its own x-z plane with y up, centred on its origin, sample (x, z) at
// (−width/2 + x·Δ, −depth/2 + z·Δ). Turned so its y is the box's z and its x the box's x, its z is the box's −y: sample
// (x, z) is the grid's column x, row rows − 1 − z.
dReal top_height(void* grid, int x, int z) {
  const auto* top = static_cast<const DentedTop*>(grid);
  const std::size_t row = top->rows - 1 - static_cast<std::size_t>(z);
  return top->height_m[row * top->columns + static_cast<std::size_t>(x)];
}

}  // namespace

void OdeEngine::dent_top(std::size_t id, const DentedTop& top) {
  Handles& ode = *ode_;
  const SceneObject& object = ode.scene->objects[id];
  if (object.dynamic || object.shape.kind != ShapeKind::box || top.columns < 2 || top.rows < 2) return;
  const auto& size_m = object.shape.box_size_m;
  const double half_z_m = 0.5 * size_m[2];
  dGeomID box = ode.geoms[id];
  const auto& q = object.orientation_wxyz;
  const Eigen::Quaterniond orientation(q[0], q[1], q[2], q[3]);
  const Eigen::Vector3d centre_m(object.position_m[0], object.position_m[1], object.position_m[2]);
  if (ode.tops[id] == nullptr) {
    ode.top_grids[id] = top;
    dHeightfieldDataID data = dGeomHeightfieldDataCreate();
    ode.top_data.push_back(data);
    // Solid below the surface down to the box's bottom, as the slab is.
    dGeomHeightfieldDataBuildCallback(data, &ode.top_grids[id], &top_height,
                                      static_cast<double>(top.columns - 1) * top.cell_x_m,
                                      static_cast<double>(top.rows - 1) * top.cell_y_m, static_cast<int>(top.columns),
                                      static_cast<int>(top.rows), 1.0, 0.0, top.floor_m + half_z_m, 0);
    dGeomHeightfieldDataSetBounds(data, top.floor_m, half_z_m);
    dGeomID field = dCreateHeightfield(dGeomGetSpace(box), data, 1);
    dGeomSetData(field, id_to_data(id));
    // Box from heightfield: x → x, y → z, z → −y.
    Eigen::Matrix3d turn;
    turn << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    const Eigen::Matrix3d rotation = orientation.toRotationMatrix() * turn;
    dMatrix3 r;
    for (int row = 0; row < 3; ++row) {
      for (int column = 0; column < 3; ++column) r[4 * row + column] = rotation(row, column);
      r[4 * row + 3] = 0.0;
    }
    dGeomSetPosition(field, centre_m.x(), centre_m.y(), centre_m.z());
    dGeomSetRotation(field, r);
    ode.tops[id] = field;
  }
  // The box below the lowest point of the surface, so only the heights are met above it.
  const double lowest_m = std::clamp(top.lowest_m, top.floor_m, half_z_m);
  dGeomBoxSetLengths(box, size_m[0], size_m[1], lowest_m + half_z_m);
  const Eigen::Vector3d box_centre_m = centre_m + orientation * Eigen::Vector3d(0.0, 0.0, 0.5 * (lowest_m - half_z_m));
  dGeomSetPosition(box, box_centre_m.x(), box_centre_m.y(), box_centre_m.z());
  // A body asleep on the box would hang over a dent made under it.
  const Eigen::AlignedBox3d slab = geom_bounds(ode.tops[id]).extend(geom_bounds(box));
  for (const std::size_t other : ode.dynamic_ids) {
    if (asleep(other) && geom_bounds(ode.geoms[other]).intersects(slab)) wake(other);
  }
}

bool OdeEngine::asleep(std::size_t id) const {
  return ode_->sleeping && ode_->sleeping->asleep(id);
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
  if (ode.sleeping) ode.sleeping->begin_step();
  for (int substep = 0; substep < substeps; ++substep) {
    hook.before_substep(substep);
    ode.record_contacts = record_contacts && substep + 1 == substeps;
    const bool recording = ode.record_contacts;
    if (recording) ode.recorded.clear();
    ode.park_escaped();
    if (ode.speculative) ode.speculative->begin_substep(substep_s);
    if (ode.sleeping) ode.sleeping->wake_touched(substep_s, ode);
    if (ode.speculative) ode.speculative->predict(ode.movers(), ode);
    if (ode.sleeping) {
      ode.collide_awake();
    } else {
      dSpaceCollide(ode.space, &ode, &Handles::near_callback);
    }
    if (ode.speculative) {
      ode.speculative->add_closing_contacts(ode);
      ode.speculative->speculate(ode.movers(), ode);
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
    hook.after_substep(substep);
  }
  ode.park_escaped();  // the world reads the state next
  if (ode.sleeping) ode.sleeping->put_rested_to_sleep(ode);
  ode.random_state = dRandGetSeed();
}

const std::vector<std::size_t>& OdeEngine::moved() const {
  return ode_->sleeping ? ode_->sleeping->moved() : ode_->dynamic_ids;
}

ContactGraph& OdeEngine::contacts() { return ode_->contact_graph; }

const std::vector<std::size_t>& OdeEngine::escaped() const { return ode_->escape_guard.escaped(); }

std::vector<RigidBodyEngine::Overlap> OdeEngine::overlaps(double min_depth_m) const {
  const Handles& ode = *ode_;
  const Scene& scene = *ode.scene;
  // Pairs by their boxes swept along x (O(n log n)), then each pair's contacts (dCollide, which changes nothing);
  // the spaces are left alone so the steps that follow meet them exactly as they were.
  struct Box {
    std::size_t id;
    Eigen::AlignedBox3d bounds;
  };
  std::vector<Box> boxes;
  for (std::size_t id = 0; id < ode.geoms.size(); ++id) boxes.push_back({id, geom_bounds(ode.geoms[id])});
  std::sort(boxes.begin(), boxes.end(), [](const Box& x, const Box& y) { return x.bounds.min().x() < y.bounds.min().x(); });
  std::vector<Overlap> found;
  const auto deepest = [&](dGeomID a, dGeomID b) {
    dContactGeom contacts[kMaxContactsPerPair];
    const int count = dCollide(a, b, kMaxContactsPerPair, contacts, sizeof(dContactGeom));
    double depth_m = 0.0;
    for (int c = 0; c < count; ++c) depth_m = std::max(depth_m, contacts[c].depth);
    return depth_m;
  };
  const auto record = [&](std::size_t a, std::size_t b, double depth_m) {
    if (depth_m > min_depth_m) found.push_back({std::min(a, b), std::max(a, b), depth_m});
  };
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& a = boxes[i];
    for (std::size_t j = i + 1; j < boxes.size() && boxes[j].bounds.min().x() <= a.bounds.max().x(); ++j) {
      const Box& b = boxes[j];
      if (!(scene.objects[a.id].dynamic || scene.objects[b.id].dynamic) || !a.bounds.intersects(b.bounds)) continue;
      record(a.id, b.id, deepest(ode.geoms[a.id], ode.geoms[b.id]));
    }
    if (ode.floor != nullptr && scene.objects[a.id].dynamic) {
      record(a.id, ode.geoms.size(), deepest(ode.geoms[a.id], ode.floor));
    }
  }
  std::sort(found.begin(), found.end(), [](const Overlap& x, const Overlap& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  return found;
}

}  // namespace impetus
