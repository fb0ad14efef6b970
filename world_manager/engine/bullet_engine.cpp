// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/bullet_engine.h"

#include "common/mesh/mesh_body.h"
#include "common/shape/mesh_geometry.h"
#include "world_manager/engine/escape_guard.h"
#include "world_manager/engine/sleeping_bodies.h"
#include "world_manager/engine/speculative_contacts.h"

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletCollision/CollisionDispatch/btUnionFind.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btMLCPSolver.h>
#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

static_assert(sizeof(btScalar) == sizeof(double), "Impetus uses Bullet's double-precision build (bullet-float64)");

namespace impetus {
namespace {

// Bullet rounds a box's and a cylinder's edges by this margin, which its contact generation (GJK) needs to be robust.
// Half a millimetre is 1 % of the 5 cm cubes the paper's task uses, and under the 1 mm a finger feels; Bullet's
// default (4 cm) would round a 5 cm cube into a ball. A sphere's and a capsule's margin is their radius: exact.
constexpr double kShapeMargin_m = 5e-4;

// The floor is a static slab, 20 km square and 2 m thick, whose top is the scene's floor height. Bullet's plane meets a
// box at one point per substep (its plane-convex test), so a box sliding on it rocks from corner to corner and its
// contacts carry a fraction of its weight; the box-box test gives the whole face. 10 km each way is far beyond any
// scene a haptic device reaches (ODE's plane is unbounded; a body past the slab's edge would fall).
constexpr double kFloorHalfWidth_m = 1e4;
constexpr double kFloorThickness_m = 2.0;

btVector3 to_bt(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
btVector3 to_bt(const Vec3& v) { return {v[0], v[1], v[2]}; }
Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// The scene's rules for two materials (scene.h): Bullet asks these for every new contact point. Every engine sets the
// same functions, so the process-wide setting is the same whichever engine set it last.
btScalar combined_friction(const btCollisionObject* a, const btCollisionObject* b) {
  return combine_friction(a->getFriction(), b->getFriction());
}
btScalar combined_restitution(const btCollisionObject* a, const btCollisionObject* b) {
  return combine_restitution(a->getRestitution(), b->getRestitution());
}
// Every object carries the scene's one contact spring and damper, so both sides agree: the pair's is either's.
btScalar combined_stiffness(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getContactStiffness(), b->getContactStiffness());
}
btScalar combined_damping(const btCollisionObject* a, const btCollisionObject* b) {
  return std::min(a->getContactDamping(), b->getContactDamping());
}

// What a mesh's shape needs kept as long as it: Bullet's view of the triangles, and the vertices turned to the body's
// principal axes where they are not the file's.
struct MeshArrays {
  std::vector<std::unique_ptr<btTriangleIndexVertexArray>> views;
  std::vector<std::unique_ptr<HugeVector<Eigen::Vector3d>>> turned_vertices_m;
};

// A mesh's triangles for Bullet (docs/meshes.md), read in place from the loaded MeshBody (which lives as long as the
// process): a static mesh as a BVH of its triangles, a dynamic one as a GImpact shape (a BVH of triangles that
// moves), its vertices turned by `to_principal` (Bullet's body frame is the principal axes of inertia).
std::unique_ptr<btCollisionShape> make_mesh_shape(const SceneObject& object, const Eigen::Matrix3d& to_principal,
                                                  MeshArrays& arrays) {
  const auto* body = dynamic_cast<const MeshBody*>(find_mesh_geometry(object.shape.mesh_hash));
  if (body == nullptr) throw SceneError("object '" + object.name + "': its mesh was not loaded");
  const TriangleMesh& mesh = body->bvh().mesh();
  const HugeVector<Eigen::Vector3d>* vertices_m = &mesh.vertices_m;
  if (!to_principal.isIdentity(0.0)) {
    auto turned = std::make_unique<HugeVector<Eigen::Vector3d>>(mesh.vertices_m.size());
    for (std::size_t k = 0; k < mesh.vertices_m.size(); ++k) (*turned)[k] = to_principal * mesh.vertices_m[k];
    vertices_m = turned.get();
    arrays.turned_vertices_m.push_back(std::move(turned));
  }
  btIndexedMesh part;
  part.m_numTriangles = static_cast<int>(mesh.triangles.size());
  part.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(mesh.triangles.data());
  part.m_triangleIndexStride = static_cast<int>(sizeof(mesh.triangles[0]));
  part.m_numVertices = static_cast<int>(vertices_m->size());
  part.m_vertexBase = reinterpret_cast<const unsigned char*>(vertices_m->data());
  part.m_vertexStride = static_cast<int>(sizeof(Eigen::Vector3d));
  part.m_indexType = PHY_INTEGER;
  part.m_vertexType = PHY_DOUBLE;
  auto array = std::make_unique<btTriangleIndexVertexArray>();
  array->addIndexedMesh(part, PHY_INTEGER);
  std::unique_ptr<btCollisionShape> out;
  if (object.dynamic) {
    auto moving = std::make_unique<btGImpactMeshShape>(array.get());
    moving->setMargin(0.0);  // a triangle's margin lies outside it: the mesh would stand off by it
    moving->updateBound();
    out = std::move(moving);
  } else {
    out = std::make_unique<btBvhTriangleMeshShape>(array.get(), true);
    out->setMargin(0.0);
  }
  arrays.views.push_back(std::move(array));
  return out;
}

std::unique_ptr<btCollisionShape> make_shape(const SceneObject& object, const Eigen::Matrix3d& to_principal,
                                             MeshArrays& arrays) {
  const Shape& shape = object.shape;
  std::unique_ptr<btCollisionShape> out;
  switch (shape.kind) {
    case ShapeKind::box:
      out = std::make_unique<btBoxShape>(to_bt(Eigen::Vector3d(shape.box_size_m[0], shape.box_size_m[1],
                                                               shape.box_size_m[2]) / 2.0));
      break;
    case ShapeKind::sphere:
      return std::make_unique<btSphereShape>(shape.radius_m);
    case ShapeKind::capsule:  // the axis is the body's z, the length the cylinder's between the caps (as ODE's)
      return std::make_unique<btCapsuleShapeZ>(shape.radius_m, shape.length_m);
    case ShapeKind::cylinder:
      out = std::make_unique<btCylinderShapeZ>(btVector3(shape.radius_m, shape.radius_m, shape.length_m / 2.0));
      break;
    case ShapeKind::mesh:
      return make_mesh_shape(object, to_principal, arrays);
    case ShapeKind::none:
      throw SceneError("object '" + object.name + "' has no shape");
  }
  out->setMargin(kShapeMargin_m);
  return out;
}

// Collects the deepest penetration of one pair (contactPairTest's answer; negative distances are depths).
struct DeepestPoint final : btCollisionWorld::ContactResultCallback {
  double depth_m = 0.0;
  btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper*, int, int,
                           const btCollisionObjectWrapper*, int, int) override {
    depth_m = std::max(depth_m, -static_cast<double>(point.getDistance()));
    return 0;
  }
};

static_assert(STATIC_SIMULATION_ISLAND_OPTIMIZATION, "ContactIslands numbers islands as this Bullet build does");

// Simulation islands joined by contact, as ODE's are by its contact joints. Bullet's own island manager joins every
// pair whose bounding boxes overlap, and Bullet widens each box by its contact breaking threshold (2 cm): resting
// bodies a centimetre apart that never touch become one island, which sleeps and wakes as one, so one pressed sphere
// in a field of resting ones keeps the whole field awake. Here a pair joins an island only when its manifold holds a
// contact point (a point leaves the manifold once the pair is apart by more than the threshold).
class ContactIslands final : public btSimulationIslandManager {
 public:
  void updateActivationState(btCollisionWorld* world, btDispatcher* dispatcher) override {
    // Each dynamic body's island starts as its own index, as Bullet's manager (built with its static-island
    // optimisation) numbers them: static bodies take no index and join no island.
    int index = 0;
    for (int i = 0; i < world->getCollisionObjectArray().size(); ++i) {
      btCollisionObject* object = world->getCollisionObjectArray()[i];
      if (!object->isStaticOrKinematicObject()) object->setIslandTag(index++);
      object->setCompanionId(-1);
      object->setHitFraction(1.0);
    }
    initUnionFind(index);
    for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(m);
      if (manifold->getNumContacts() == 0) continue;
      const btCollisionObject* a = manifold->getBody0();
      const btCollisionObject* b = manifold->getBody1();
      if (a->mergesSimulationIslands() && b->mergesSimulationIslands()) {
        getUnionFind().unite(a->getIslandTag(), b->getIslandTag());
      }
    }
  }
};

// Bullet's discrete world with ContactIslands for its island manager.
class ContactIslandWorld final : public btDiscreteDynamicsWorld {
 public:
  ContactIslandWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase, btConstraintSolver* solver,
                     btCollisionConfiguration* configuration)
      : btDiscreteDynamicsWorld(dispatcher, broadphase, solver, configuration) {
    if (m_ownsIslandManager) {
      m_islandManager->~btSimulationIslandManager();
      btAlignedFree(m_islandManager);
    }
    m_islandManager = &islands_;
    m_ownsIslandManager = false;
  }

 private:
  ContactIslands islands_;
};

// The scene's solver (BulletParams::Solver); `dantzig` is the direct solver's LCP method and must outlive it.
std::unique_ptr<btSequentialImpulseConstraintSolver> make_solver(const BulletParams& params, btDantzigSolver& dantzig) {
  if (params.solver == BulletParams::Solver::direct) return std::make_unique<btMLCPSolver>(&dantzig);
  return std::make_unique<btSequentialImpulseConstraintSolver>();
}

}  // namespace

struct BulletEngine::World final : EscapeGuard::Engine {
  // GImpact's algorithms (a moving mesh against anything) join the dispatcher's.
  explicit World(const Scene& s) : scene(&s) { btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher); }

  const Scene* scene;
  // Declared before the world, so the world (which holds them) goes first.
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btDantzigSolver dantzig;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver = make_solver(scene->physics.bullet, dantzig);
  MeshArrays mesh_arrays;  // the meshes' triangles, for their shapes
  // Per object, Bullet's body frame in ours: its principal axes of inertia (Bullet takes a diagonal inertia), the
  // identity but for a mesh whose principal axes are not its file's. Bullet's orientation is ours times this.
  std::vector<btQuaternion> principal;
  Eigen::Quaterniond ours(std::size_t id, const btQuaternion& q) const {
    const btQuaternion o = q * principal[id].inverse();
    return Eigen::Quaterniond(o.w(), o.x(), o.y(), o.z());
  }
  std::vector<std::unique_ptr<btCollisionShape>> shapes;  // per object, the floor's last
  std::vector<std::unique_ptr<btRigidBody>> bodies;       // per object (static ones have no mass); the floor last
  // Dented tops (dent_top): per object, the heightfield beside its box (nullptr: none), and its shape.
  std::vector<std::unique_ptr<btRigidBody>> tops;
  std::vector<std::unique_ptr<btCollisionShape>> top_shapes;
  ContactIslandWorld world{&dispatcher, &broadphase, solver.get(), &configuration};

  std::vector<Eigen::Matrix3d> inverse_inertia_body;  // per object; zero for static ones
  std::vector<std::size_t> dynamic_ids;               // ascending
  std::vector<std::size_t> moved;
  std::vector<bool> awake_in_step;  // per object: awake at the start of the step or after one of its substeps
  std::vector<bool> parked;                           // taken out of the world by the escape guard
  // The forces and torques given for the next substep (add_force), per object: they enter as the velocity change
  // they cause over the substep, v += F·h/m and ω += I⁻¹·τ·h, set on the body before Bullet steps. Given to Bullet as
  // forces instead, a torque goes wrong: Bullet 3.24's friction rows see the external force's velocity change but not
  // the external torque's, while the step applies both, so the torque's spin at the contact points passes as sliding
  // the friction never saw (a 5 cm cube on the floor given a 6 mN·m torque slides at ω·h·r = 0.8 mm/s forever).
  std::vector<Eigen::Vector3d> pending_force_N;
  std::vector<Eigen::Vector3d> pending_torque_Nm;
  std::vector<std::size_t> pushed;  // the objects with a pending force, in the order they were first given one
  ContactGraph contact_graph;
  double contact_stiffness_Npm = 0.0;  // the scene's contact spring (or the engine-neutral default)
  double contact_damping_Nspm = 0.0;
  EscapeGuard escape_guard{0};

  btRigidBody& body(std::size_t id) const { return *bodies[id]; }
  std::size_t object_count() const { return scene->objects.size(); }
  bool is_dynamic(std::size_t id) const { return id < object_count() && scene->objects[id].dynamic; }

  void push(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) {
    if (pending_force_N[id].isZero(0.0) && pending_torque_Nm[id].isZero(0.0)) pushed.push_back(id);
    pending_force_N[id] += force_N;
    pending_torque_Nm[id] += torque_Nm;
  }
  // The pending forces as the velocity change of one substep of h (explicit Euler, as Bullet integrates forces).
  void apply_pushes(double h) {
    for (const std::size_t id : pushed) {
      btRigidBody& b = body(id);
      if (!parked[id]) {
        b.setLinearVelocity(b.getLinearVelocity() + to_bt(pending_force_N[id]) * (b.getInvMass() * h));
        b.setAngularVelocity(b.getAngularVelocity() + b.getInvInertiaTensorWorld() * to_bt(pending_torque_Nm[id]) * h);
      }
      pending_force_N[id].setZero();
      pending_torque_Nm[id].setZero();
    }
    pushed.clear();
  }

  // EscapeGuard::Engine
  std::optional<EscapeGuard::BodyState> escape_state(std::size_t id) const override {
    if (!is_dynamic(id) || parked[id]) return std::nullopt;
    const btRigidBody& b = body(id);
    const Eigen::Quaterniond q = ours(id, b.getWorldTransform().getRotation());
    return EscapeGuard::BodyState{to_eigen(b.getWorldTransform().getOrigin()), to_eigen(b.getLinearVelocity()),
                                  to_eigen(b.getAngularVelocity()), Eigen::Vector4d(q.w(), q.x(), q.y(), q.z())};
  }
  void park(std::size_t id, const Eigen::Vector3d& position_m, bool reset_orientation) override {
    btRigidBody& b = body(id);
    world.removeRigidBody(&b);  // out of the solver, gravity and collisions
    btTransform transform = b.getWorldTransform();
    if (reset_orientation) transform.setRotation(principal[id]);
    transform.setOrigin(to_bt(position_m));
    b.setWorldTransform(transform);
    b.setLinearVelocity(btVector3(0, 0, 0));
    b.setAngularVelocity(btVector3(0, 0, 0));
    parked[id] = true;
  }

  // The contacts of the last substep into the graph, each with the normal force it pushed with: the impulse the
  // solver applied over the substep, over its length. A point not yet touching that the solver did not press is left
  // out (the pair had not met).
  void record_graph(double substep_s) {
    contact_graph.reset(object_count());
    const auto id_of = [&](const btCollisionObject* object) {
      const std::size_t id = static_cast<std::size_t>(object->getUserIndex());
      return is_dynamic(id) ? static_cast<std::int32_t>(id) : ContactGraph::kStatic;
    };
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
      const std::int32_t a = id_of(manifold->getBody0());
      const std::int32_t b = id_of(manifold->getBody1());
      if (a == ContactGraph::kStatic && b == ContactGraph::kStatic) continue;
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold->getContactPoint(p);
        const double normal_force_N = std::max(0.0, static_cast<double>(point.getAppliedImpulse())) / substep_s;
        if (point.getDistance() > 0.0 && !(normal_force_N > 0.0)) continue;
        // Bullet's normal is on body 1, pointing to body 0: the contact pushes body 0 along it.
        const Eigen::Vector3d normal = to_eigen(point.m_normalWorldOnB);
        if (!(normal.squaredNorm() > 0.0) || !normal.allFinite()) continue;
        if (a != ContactGraph::kStatic) contact_graph.add(a, b, normal, point.m_combinedFriction, normal_force_N);
        if (b != ContactGraph::kStatic) contact_graph.add(b, a, -normal, point.m_combinedFriction, normal_force_N);
      }
    }
    contact_graph.finish();
  }
};

BulletEngine::BulletEngine(const Scene& scene) : bullet_(std::make_unique<World>(scene)) {
  World& w = *bullet_;
  // A round body on a box (a cylinder's rim, a capsule's side) gets several points of its contact in every substep,
  // found by perturbing the pair; by default Bullet finds one point per substep and builds the patch over several.
  w.configuration.setConvexConvexMultipointIterations();
  gCalculateCombinedFrictionCallback = &combined_friction;
  gCalculateCombinedRestitutionCallback = &combined_restitution;
  gCalculateCombinedContactStiffnessCallback = &combined_stiffness;
  gCalculateCombinedContactDampingCallback = &combined_damping;
  // The rest rule of sleeping_bodies.h: speeds under its thresholds for its rest time.
  gDeactivationTime = SleepingBodies::kRestBeforeSleep_s;

  w.world.setGravity(to_bt(scene.gravity_mps2));
  // Bounding boxes of the bodies that move only: static and sleeping ones keep theirs (Bullet's default refreshes
  // every body's each substep, which a world of resting bodies would pay for).
  w.world.setForceUpdateAllAabbs(false);
  btContactSolverInfo& solver = w.world.getSolverInfo();
  solver.m_numIterations = scene.physics.bullet.solver_iterations;
  // The direct solver solves each island alone (Bullet's default joins small islands into batches of 128 rows, which
  // the iterative solver sweeps cheaply but a direct solve pays for cubically).
  if (scene.physics.bullet.solver == BulletParams::Solver::direct) solver.m_minimumSolverBatchSize = 1;
  // The contact spring corrects penetration through the solver's velocities, as ODE's ERP does; Bullet's split
  // impulse (a separate position correction) would be a second model.
  solver.m_splitImpulse = 0;
  solver.m_restitutionVelocityThreshold = kBounceThreshold_mps;
  // Friction in two fixed tangential directions per contact point, kept for the point's life: a pyramid fixed to the
  // contact, as ODE's. Bullet's default is one direction, along the sliding velocity (for a body at rest an arbitrary
  // one): a push across it meets no friction, so a cube pushed below its static friction creeps. Directions that turn
  // with the sliding velocity flip where a slide reverses, and the warm-started friction impulse then lands on the
  // new directions: a cube whose slide reversed on a ramp started to spin, tipped and slid under a finger holding it
  // (hard case 12a).
  solver.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                         SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
  // Every contact is the scene's spring and damper (the engine-neutral default when the scene gives none: ODE's
  // default contact at 5 ms substeps, scene.h), which Bullet turns into ERP and CFM per substep as ODE's are.
  const PhysicsParams& physics = scene.physics;
  const double stiffness_Npm = std::isnan(physics.contact_stiffness_Npm) ? PhysicsParams::kDefaultContactStiffness_Npm
                                                                         : physics.contact_stiffness_Npm;
  const double damping_Nspm = std::isnan(physics.contact_damping_Nspm) ? PhysicsParams::kDefaultContactDamping_Nspm
                                                                       : physics.contact_damping_Nspm;

  w.contact_stiffness_Npm = stiffness_Npm;
  w.contact_damping_Nspm = damping_Nspm;
  const std::size_t count = scene.objects.size();
  w.inverse_inertia_body.assign(count, Eigen::Matrix3d::Zero());
  w.principal.assign(count, btQuaternion::getIdentity());
  w.tops.resize(count);
  w.parked.assign(count, false);
  w.pending_force_N.assign(count, Eigen::Vector3d::Zero());
  w.pending_torque_Nm.assign(count, Eigen::Vector3d::Zero());
  w.contact_graph.reset(count);
  w.escape_guard = EscapeGuard(count);
  const auto set_surface = [&](btRigidBody& b, const Material& material, std::size_t id) {
    b.setFriction(material.dynamic_friction);  // one coefficient, the dynamic one, as ODE is given (ode_engine.cpp)
    b.setRestitution(material.restitution);
    b.setContactStiffnessAndDamping(stiffness_Npm, damping_Nspm);
    b.setUserIndex(static_cast<int>(id));
  };
  for (std::size_t id = 0; id < count; ++id) {
    const SceneObject& object = scene.objects[id];
    const double mass_kg = object.dynamic ? object.mass_kg : 0.0;
    btVector3 inertia(0, 0, 0);
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // the principal axes, columns in our body frame
    if (object.dynamic) {
      // The primitives' inertia is diagonal in the body frame (shape.h); a mesh's may not be, and Bullet takes a
      // diagonal one: its body frame is then the principal axes, I = R·diag(λ)·Rᵀ, R a rotation.
      const Eigen::Matrix3d exact = inertia_kgm2(object.shape, object.mass_kg);
      Eigen::Vector3d principal_kgm2 = exact.diagonal();
      const double off_diagonal = (exact - Eigen::Matrix3d(exact.diagonal().asDiagonal())).cwiseAbs().maxCoeff();
      if (off_diagonal > 1e-12 * exact.trace()) {
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(exact);
        axes = solver.eigenvectors();
        if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
        principal_kgm2 = solver.eigenvalues();
      }
      inertia = to_bt(principal_kgm2);
      w.inverse_inertia_body[id] = exact.inverse();
    }
    const Eigen::Quaterniond turn(axes);
    w.principal[id] = btQuaternion(turn.x(), turn.y(), turn.z(), turn.w());
    w.shapes.push_back(make_shape(object, axes.transpose(), w.mesh_arrays));
    btTransform transform;
    const auto& q = object.orientation_wxyz;
    transform.setRotation(btQuaternion(q[1], q[2], q[3], q[0]) * w.principal[id]);
    transform.setOrigin(to_bt(object.position_m));
    btRigidBody::btRigidBodyConstructionInfo info(mass_kg, nullptr, w.shapes.back().get(), inertia);
    info.m_startWorldTransform = transform;
    w.bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody& b = *w.bodies.back();
    set_surface(b, object.material, id);
    if (object.dynamic) {
      b.setLinearVelocity(to_bt(object.linear_velocity_mps));
      b.setAngularVelocity(to_bt(object.angular_velocity_radps));
      if (scene.physics.auto_disable) {
        b.setSleepingThresholds(SleepingBodies::kSleepSpeed_mps, SleepingBodies::kSleepAngularSpeed_radps);
      } else {
        b.setActivationState(DISABLE_DEACTIVATION);
      }
      if (scene.physics.speculative_contacts) {
        // Continuous collision for a body that moves more than a third of its smallest size in a substep: swept as a
        // sphere of a third of that size, so it stops at what it would pass through.
        const Eigen::AlignedBox3d bounds = world_bounds(object.shape, BodyPose{});
        const double smallest_m = bounds.sizes().minCoeff();
        b.setCcdMotionThreshold(smallest_m / 3.0);
        b.setCcdSweptSphereRadius(smallest_m / 3.0);
      }
      w.dynamic_ids.push_back(id);
    }
    w.world.addRigidBody(&b);
  }
  if (scene.floor.present) {
    // The floor as a slab whose top is the floor (kFloorHalfWidth_m says why not Bullet's plane).
    auto slab = std::make_unique<btBoxShape>(btVector3(kFloorHalfWidth_m, kFloorHalfWidth_m, kFloorThickness_m / 2.0));
    slab->setMargin(kShapeMargin_m);
    w.shapes.push_back(std::move(slab));
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, w.shapes.back().get());
    info.m_startWorldTransform.setIdentity();
    info.m_startWorldTransform.setOrigin(btVector3(0.0, 0.0, scene.floor.height_m - kFloorThickness_m / 2.0));
    w.bodies.push_back(std::make_unique<btRigidBody>(info));
    set_surface(*w.bodies.back(), scene.floor.material, count);
    w.world.addRigidBody(w.bodies.back().get());
  }
  w.moved = w.dynamic_ids;
}

BulletEngine::~BulletEngine() = default;

void BulletEngine::read_state(std::size_t id, ObjectState& out) const {
  const btRigidBody& b = bullet_->body(id);
  out.pose.position_m = to_eigen(b.getWorldTransform().getOrigin());
  out.pose.orientation = bullet_->ours(id, b.getWorldTransform().getRotation());
  out.velocity_mps = to_eigen(b.getLinearVelocity());
  out.angular_velocity_radps = to_eigen(b.getAngularVelocity());
}

const Eigen::Matrix3d& BulletEngine::inverse_inertia_body(std::size_t id) const {
  return bullet_->inverse_inertia_body[id];
}

void BulletEngine::velocity(std::size_t id, Eigen::Vector3d& velocity_mps, Eigen::Vector3d& angular_radps) const {
  const btRigidBody& b = bullet_->body(id);
  velocity_mps = to_eigen(b.getLinearVelocity());
  angular_radps = to_eigen(b.getAngularVelocity());
}

void BulletEngine::set_velocity(std::size_t id, const Eigen::Vector3d& velocity_mps,
                                const Eigen::Vector3d& angular_radps) {
  btRigidBody& b = bullet_->body(id);
  wake(id);
  b.setLinearVelocity(to_bt(velocity_mps));
  b.setAngularVelocity(to_bt(angular_radps));
}

void BulletEngine::wake(std::size_t id) {
  if (!bullet_->parked[id]) bullet_->body(id).activate(true);
}

bool BulletEngine::asleep(std::size_t id) const {
  return !bullet_->parked[id] && bullet_->body(id).getActivationState() == ISLAND_SLEEPING;
}

void BulletEngine::add_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) {
  if (bullet_->parked[id]) return;
  bullet_->body(id).activate(true);
  bullet_->push(id, force_N, torque_Nm);
}

void BulletEngine::add_force_at(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& point_m) {
  if (bullet_->parked[id]) return;
  btRigidBody& b = bullet_->body(id);
  b.activate(true);
  const Eigen::Vector3d arm_m = point_m - to_eigen(b.getCenterOfMassPosition());
  bullet_->push(id, force_N, arm_m.cross(force_N));
}

void BulletEngine::step(int substeps, double substep_s, bool record_contacts, SubstepHook& hook) {
  World& w = *bullet_;
  // Moved: awake at the start of the step or after any substep.
  w.moved.clear();
  w.awake_in_step.assign(w.object_count(), false);
  const auto note_awake = [&] {
    for (const std::size_t id : w.dynamic_ids) {
      if (!w.parked[id] && w.body(id).isActive()) w.awake_in_step[id] = true;
    }
  };
  note_awake();
  if (w.scene->physics.bullet.solver == BulletParams::Solver::direct) {
    // The direct solver's softness: Bullet 3.24's MLCP leaves out each contact's own CFM (the spring given by
    // setContactStiffnessAndDamping, which the sequential solver uses) and adds the global CFM over h to the
    // diagonal of every row instead. ODE's world CFM, 1/(k·h + c), likewise softens every row of a contact, the
    // normal and the friction ones: so a resting load sits at weight/k as on the sequential solver and on ODE, and
    // a face resting on four points stays a regular system the pivoting solves (rigid rows make it singular, and
    // the solver falls back to sequential impulses).
    w.world.getSolverInfo().m_globalCfm = 1.0 / (w.contact_stiffness_Npm * substep_s + w.contact_damping_Nspm);
  }
  for (int substep = 0; substep < substeps; ++substep) {
    hook.before_substep(substep);
    w.apply_pushes(substep_s);
    w.escape_guard.check(w.dynamic_ids, w);
    // One substep of exactly substep_s (no fixed-step interpolation); Bullet clears the forces after it.
    w.world.stepSimulation(substep_s, 0);
    note_awake();
    hook.after_substep(substep);
  }
  w.escape_guard.check(w.dynamic_ids, w);  // the world reads the state next
  if (record_contacts) w.record_graph(substep_s);
  for (const std::size_t id : w.dynamic_ids) {
    if (w.awake_in_step[id]) w.moved.push_back(id);
  }
}

const std::vector<std::size_t>& BulletEngine::moved() const { return bullet_->moved; }

ContactGraph& BulletEngine::contacts() { return bullet_->contact_graph; }

const std::vector<std::size_t>& BulletEngine::escaped() const { return bullet_->escape_guard.escaped(); }

void BulletEngine::dent_top(std::size_t id, const DentedTop& top) {
  World& w = *bullet_;
  const SceneObject& object = w.scene->objects[id];
  if (object.dynamic || object.shape.kind != ShapeKind::box || top.columns < 2 || top.rows < 2) return;
  const auto& size_m = object.shape.box_size_m;
  const double half_z_m = 0.5 * size_m[2];
  const auto& q = object.orientation_wxyz;
  const Eigen::Quaterniond orientation(q[0], q[1], q[2], q[3]);
  const Eigen::Vector3d centre_m(object.position_m[0], object.position_m[1], object.position_m[2]);
  const auto placed = [&](double up_m) {
    btTransform transform;
    transform.setRotation(btQuaternion(q[1], q[2], q[3], q[0]));
    transform.setOrigin(to_bt(Eigen::Vector3d(centre_m + orientation * Eigen::Vector3d(0.0, 0.0, up_m))));
    return transform;
  };
  if (!w.tops[id]) {
    // Bullet's heightfield with z up reads sample (x, y) at y·width + x, as the grid is laid out, centred on its
    // origin and on the middle of its bounds; one unit between samples, scaled to the cells.
    auto field = std::make_unique<btHeightfieldTerrainShape>(static_cast<int>(top.columns), static_cast<int>(top.rows),
                                                             top.height_m, top.floor_m, half_z_m, 2, false);
    field->setLocalScaling(btVector3(top.cell_x_m, top.cell_y_m, 1.0));
    btRigidBody::btRigidBodyConstructionInfo info(0.0, nullptr, field.get());
    info.m_startWorldTransform = placed(0.5 * (top.floor_m + half_z_m));
    auto body = std::make_unique<btRigidBody>(info);
    const btRigidBody& box = w.body(id);
    body->setFriction(box.getFriction());
    body->setRestitution(box.getRestitution());
    body->setContactStiffnessAndDamping(w.contact_stiffness_Npm, w.contact_damping_Nspm);
    body->setUserIndex(static_cast<int>(id));
    // Only touching points push: a ball resting on the heights also lies within Bullet's contact threshold of the
    // neighbouring triangles' edges, whose normals lean; given to the solver, they rolled a 3 mm ball at rest on flat
    // heights away at 4 cm/s.
    body->setContactProcessingThreshold(0.0);
    w.world.addRigidBody(body.get());
    w.top_shapes.push_back(std::move(field));
    w.tops[id] = std::move(body);
  }
  // The box below the lowest point of the surface, so only the heights are met above it.
  const double lowest_m = std::clamp(top.lowest_m, top.floor_m, half_z_m);
  btRigidBody& box = w.body(id);
  box.getCollisionShape()->setLocalScaling(btVector3(1.0, 1.0, (lowest_m + half_z_m) / size_m[2]));
  box.setWorldTransform(placed(0.5 * (lowest_m - half_z_m)));
  w.world.updateSingleAabb(&box);
  // A body asleep on the box would hang over a dent made under it.
  btVector3 slab_min, slab_max, top_min, top_max;
  box.getAabb(slab_min, slab_max);
  w.tops[id]->getAabb(top_min, top_max);
  slab_min.setMin(top_min);
  slab_max.setMax(top_max);
  for (const std::size_t other : w.dynamic_ids) {
    if (!asleep(other)) continue;
    btVector3 body_min, body_max;
    w.body(other).getAabb(body_min, body_max);
    if (TestAabbAgainstAabb2(body_min, body_max, slab_min, slab_max)) wake(other);
  }
}

std::vector<RigidBodyEngine::Overlap> BulletEngine::overlaps(double min_depth_m) const {
  World& w = *bullet_;
  std::vector<Overlap> found;
  const std::size_t count = w.object_count();
  const auto deepest = [&](std::size_t a, std::size_t b) {
    DeepestPoint deepest_point;
    w.world.contactPairTest(w.bodies[a].get(), w.bodies[b].get(), deepest_point);
    return deepest_point.depth_m;
  };
  for (std::size_t a = 0; a < count; ++a) {
    btVector3 a_min, a_max;
    w.body(a).getAabb(a_min, a_max);
    for (std::size_t b = a + 1; b < count; ++b) {
      if (!(w.is_dynamic(a) || w.is_dynamic(b))) continue;
      btVector3 b_min, b_max;
      w.body(b).getAabb(b_min, b_max);
      if (!TestAabbAgainstAabb2(a_min, a_max, b_min, b_max)) continue;
      if (const double depth_m = deepest(a, b); depth_m > min_depth_m) found.push_back({a, b, depth_m});
    }
    if (w.scene->floor.present && w.is_dynamic(a)) {
      if (const double depth_m = deepest(a, count); depth_m > min_depth_m) found.push_back({a, count, depth_m});
    }
  }
  return found;
}

}  // namespace impetus
