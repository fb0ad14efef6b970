// SPDX-License-Identifier: Apache-2.0
#pragma once
// What crosses the world link and the device port (docs/architecture.md §1, §2), as the nodes and algorithms see it:
// plain data, fixed capacity (the 1 kHz path never allocates), SI units, world frame (right-handed, z up).
//
// These are not the bytes on a wire. Each transport encodes them its own way (common/link/shm/wire_frames.h seals
// them with a checksum in a fixed layout; the in-process link hands them over as they are) and validates what it
// receives, so a frame an algorithm sees is always usable: counts within capacity, numbers finite, normals unit.

#include "common/contract/vec3.h"
#include "common/shape/shape_descriptor.h"

#include <cstdint>
#include <type_traits>

namespace impetus {

// One finger of a haptic session (docs/architecture.md §1): a report and a plane frame name the endpoint they belong
// to, and the world keys what it applies by (haptic session, endpoint, object).
using EndpointId = std::uint32_t;

inline constexpr std::uint32_t kMaxPlanes = 64;          // planes in one world → haptic frame
// Endpoints one world serves at once, over all its haptic controllers (docs/architecture.md §1): two hands of four
// fingers, or several users with a finger or two each.
inline constexpr std::uint32_t kMaxEndpoints = 8;
// Fingers one device may serve (a SPIDAR with a string set per finger): each is an endpoint of the world.
inline constexpr std::uint32_t kMaxFingers = kMaxEndpoints;
inline constexpr std::uint32_t kMaxImpulseEntries = 64;  // objects with a running impulse total in one report

enum class Coupling : std::uint32_t {
  impulse = 0,   // paper §2.2: the haptic side integrates the force, the world applies the impulse
  position = 1,  // the paper's "previous method": the world samples the finger and applies a penalty force
  local = 2,     // paper §6.3: the haptic side also moves the touched object between world steps
};
const char* to_string(Coupling coupling);

// Contacts of one object that the local response model respects (paper §6.3).
inline constexpr std::uint32_t kMaxLocalContacts = 4;

// Plane flags.
inline constexpr std::uint32_t kPlaneDynamic = 1u << 0;  // the object moves; impulses on it are applied by the world
// The object is fixed but yields where it is pressed (a plastic or elastic slab, world_manager/deform/
// deformable_surface.h): its share of the reaction gets an entry (with where it pressed, ObjectImpulse::press_*)
// instead of the static total.
inline constexpr std::uint32_t kPlaneDeformable = 1u << 1;
// A plane's shape travels in Plane::shape (a tagged descriptor, common/shape/shape_descriptor.h), not in flags.

// LocalContact flags.
// The other side holds a push along −normal: static geometry, or a body joined to static geometry by a chain of
// contacts that each take the push within their friction cone (world_manager/features/contact_graph.h). Without it the
// contact carries the object's weight in the local model but gives way to the finger's push.
inline constexpr std::uint32_t kContactHolds = 1u << 0;

// One contact of a dynamic object with the rest of the world, as the world saw it in its last substep: a unilateral
// constraint for the haptic side's local model (haptic_controller/local_dynamics.h). Or one it is about to have: the
// floor, or a table's top, below a body that rests on nothing yet, gap_m away (the model's body stops there, as the
// world's will).
struct LocalContact {
  Vec3 normal{};          // unit; the direction the contact pushes the object (out of the other body)
  double friction = 0.0;  // Coulomb coefficient of the pair, dimensionless, >= 0
  // The other body, when it is a dynamic one: the velocity of its centre of mass (m/s, world frame) and its inverse
  // mass (1/kg). Zero inverse mass: static geometry, or nothing known; the model then gives it no inertia.
  Vec3 other_velocity_mps{};
  double other_inverse_mass_per_kg = 0.0;
  std::uint32_t flags = 0;  // kContactHolds
  // How far the object is from the other side along the normal (m, >= 0): 0 for a contact the world saw, more for a
  // support it has not reached yet.
  double gap_m = 0.0;
};

// One plane of paper §3.1: the nearest surface point of an object to the finger and the outward normal there, plus
// what the haptic side needs for friction (§6.2) and for splitting the reaction among objects.
struct Plane {
  std::int32_t object_id = -1;  // index of the object in the scene; stable for the whole run
  std::uint32_t flags = 0;
  Vec3 point_m{};                 // nearest surface point to the finger
  Vec3 normal{};                  // unit, pointing out of the object toward the finger side
  Vec3 com_m{};                   // object's centre of mass
  Vec3 velocity_mps{};            // linear velocity of the centre of mass
  Vec3 angular_velocity_radps{};  // angular velocity, world frame
  double static_friction = 0.0;   // coefficient, dimensionless
  double dynamic_friction = 0.0;  // coefficient, dimensionless, <= static_friction
  // How far from point_m the plane still describes the object (common/shape/shape.h plane_extent_m): a
  // sphere's radius, a box's diagonal. 0: unbounded (the floor).
  double extent_m = 0.0;
  // A deformable object's surface under the finger (kPlaneDeformable; world_manager/deform/deformable_material.h): the
  // push it holds without yielding (N; 0: it yields to any push, or is rigid), how far the surface under the pad's
  // centre goes in per N·s of push beyond that (m/(N·s); 0: it does not yield between frames), the radius of the
  // pad the push is spread over (m), and how much further in the surface can go at point_m (m; the slab's unyielding
  // floor), so the haptic side yields it locally as the world will (haptic_controller/local_yield.h).
  double yield_force_N = 0.0;
  double yield_depth_mpNs = 0.0;
  double yield_radius_m = 0.0;
  double yield_room_m = 0.0;
  // An elastic surface (world_manager/deform/elastic_membrane.h): how far the surface under the pad's centre goes in
  // per newton of steady push (m/N; 0: not elastic), so the haptic side yields it under the finger at 1 kHz as the
  // world's surface will settle, the patch of heights carrying the rest (haptic_controller/local_yield.h).
  double yield_compliance_mpN = 0.0;
  // The body's shape (kind none for the floor), so the haptic side takes the plane again from it every tick
  // (common/shape/shape.h retake_plane). For a kind whose traits carry axes, the body's x and y axes in the world frame
  // (unit, orthogonal; z = x × y) about its centre com_m; zero otherwise (a sphere's plane carries its centre as
  // point_m − radius·normal).
  Shape shape;
  Vec3 body_axis_x{};
  Vec3 body_axis_y{};
  // Local response model for the coming world period (paper §6.3). Zero means "not provided": the haptic
  // side must then treat the object as immovable between world steps.
  double inverse_mass_per_kg = 0.0;
  std::array<double, 9> inverse_inertia_world{};  // row-major, 1/(kg·m²), about the centre of mass
  // Local coupling only: the object's contacts (floor, walls, other objects) at the end of the step, so the local
  // model cannot move it into them and applies their Coulomb friction (a cube sliding on the floor loses μ·g·Δt of
  // speed per tick, as in the world). Other couplings leave them empty.
  std::uint32_t local_contact_count = 0;
  std::array<LocalContact, kMaxLocalContacts> local_contacts{};
};

// A deformable surface around the proxy as heights (world_manager/deform/deformable_surface.h): a square of
// kDentPatchSide × kDentPatchSide samples `spacing_m` apart, sample (i, j) at origin_m + i·spacing·axis_x +
// j·spacing·axis_y + height_m[j·kDentPatchSide + i]·(axis_x × axis_y), the surface bilinear between them. The haptic
// side takes the object's plane again from it under the proxy every tick (haptic_controller/local_yield.h), as a
// shape's plane is taken again: a plane alone goes stale as the finger moves over a dent. 32 × 32 samples (8 KB):
// a cell apart (1 mm by default), ±15.5 mm about the proxy, the travel of a 15 cm/s stroke over two 10 Hz periods;
// a faster finger gets samples further apart rather than a patch it leaves (deformable_surface.h patch_about).
inline constexpr std::uint32_t kDentPatchSide = 32;
struct DentPatch {
  std::int32_t object_id = -1;  // the deformable object; -1: no patch
  Vec3 origin_m{};
  Vec3 axis_x{};                // unit, orthogonal to axis_y; their cross product is the surface's outward normal
  Vec3 axis_y{};
  double spacing_m = 0.0;       // > 0 when object_id >= 0
  std::array<double, kDentPatchSide * kDentPatchSide> height_m{};
};

// World → haptic, published once per world step i (docs/architecture.md §1.1 step 4).
struct PlaneFrame {
  std::uint64_t frame_index = 0;       // i; 0 is the first frame of a world session
  std::uint64_t world_session = 0;     // changes when the world manager restarts
  EndpointId endpoint = 0;             // the finger these planes surround
  std::uint64_t report_tick_applied = 0;  // tick of the last haptic report whose impulses the world applied
  std::uint64_t report_session_applied = 0;  // haptic session of that report (0 if none yet)
  double world_time_s = 0.0;           // simulated time at the end of this step
  double world_period_s = 0.0;         // T_w
  Coupling coupling = Coupling::impulse;
  std::uint32_t plane_count = 0;
  // Haptic parameters from the scene; the haptic controller's flags override them.
  double stiffness_Npm = 0.0;
  double damping_Nspm = 0.0;
  // Local coupling: the scene's gravity and the world's integration step inside its period (T_w / substeps), so the
  // haptic side's local model integrates the drift (gravity, supports, friction) on the same grid as the world.
  Vec3 gravity_mps2{};
  double world_substep_s = 0.0;  // 0: unknown (the model then applies the drift every tick)
  // The scene's base reach radius: the world sent every object within it of the proxy, and nothing says what lies
  // beyond, so the planes describe the world only that far (the god-object's bound on a meaningful solution).
  // 0: unknown, no bound.
  double reach_radius_m = 0.0;
  // The passivity layer (world_manager/couplings/passivity_layer.h, haptic_controller/hand_port.h): 1 when it is on,
  // and the energy the world has handed back to this endpoint's hand since the world session began, J (a running
  // total: what the objects gave the port, and the hand's input they did not take). The hand may give the finger no
  // more than it took from it and was handed back; 0 with the layer off.
  std::uint32_t port_layer = 0;
  double port_returned_J = 0.0;
  DentPatch dent_patch;  // the nearest deformable surface under the proxy, if any
  std::array<Plane, kMaxPlanes> planes{};
};

// Running impulse on one object since the haptic session started (never reset while the session lives), so the world
// applies `total - applied_so_far` whatever the timing and nothing is lost or counted twice (docs/architecture.md §2).
struct ObjectImpulse {
  std::int32_t object_id = -1;
  // Incremented by the haptic side each time it (re)allocates an entry for this object: a new epoch restarts the
  // total from zero, so the world resets its baseline instead of seeing a negative or huge difference.
  std::uint32_t epoch = 0;
  Vec3 impulse_Ns{};              // ∑ −f_k·Δt over ticks, shared to this object (paper §3.4)
  Vec3 angular_impulse_Nms{};     // ∑ (contact − CoM) × (−f_k·Δt), about the centre of mass
  // First moments in time, ∑ impulse_k·t_k with t_k the haptic session time of tick k (N·s², N·m·s²). With the
  // report's haptic_time_s they tell the world *when* within its period the impulse was rendered, so local coupling
  // applies it at that time and the world's next state agrees with what the haptic side showed (world.h).
  Vec3 impulse_moment_Nss{};
  Vec3 angular_impulse_moment_Nmss{};
  // The energy the hand put in behind this impulse, J: Σ max(0, J_k·v_k), each tick's share J_k times the finger's
  // velocity over the tick before (the hand's work against the displayed force, by a passivity observer's rectangle
  // rule), where it pushed. The world holds what its couplings give the object to it
  // (world_manager/couplings/passivity_layer.h).
  double hand_input_J = 0.0;
  // Where the object's surface was pressed (the push into it beyond yield, p_k, at the proxy x_k): Σ p_k (N·s),
  // Σ p_k·x_k (N·s·m, world frame) and Σ p_k·x_k·x_kᵀ (N·s·m², the symmetric matrix's xx, xy, xz, yy, yz, zz). The
  // differences over a world period give the push, where it was centred, and how it spread along the surface (a
  // steady straight stroke is recovered exactly), so a deformable object dents along the finger's path
  // (world_manager/deform/press_path.h). Moments in space, not in time: they stay as precise after hours as at the
  // start. Zero for any object but a deformable one (kPlaneDeformable).
  double press_Ns = 0.0;
  Vec3 press_point_Nsm{};
  std::array<double, 6> press_point2_Nsm2{};
  std::uint64_t last_tick = 0;    // last haptic tick that added to this entry
};

// Haptic → world, published every haptic tick (docs/architecture.md §1.2).
struct HapticReport {
  std::uint64_t tick = 0;           // haptic tick j of this session
  std::uint64_t haptic_session = 0; // nonzero; changes when the haptic controller restarts
  EndpointId endpoint = 0;          // the finger this report is about
  // The world session whose frames the totals below were rendered against (0: no frame seen yet). A world applies
  // only reports of its own session: when a restarted world's first frame arrives the haptic side starts its totals
  // afresh (ImpulseAccumulator), so nothing rendered against the dead world is applied to the new one.
  std::uint64_t world_session = 0;
  double haptic_time_s = 0.0;       // session time at this tick
  Vec3 finger_m{};                  // C_j
  Vec3 finger_velocity_mps{};
  // D_j, the god-object proxy: always outside every plane, so the world extracts the next planes around it rather
  // than around a finger that may have pushed deep into (or through) a thin object.
  Vec3 proxy_m{};
  Vec3 force_N{};                   // f_j, the force on the finger at this tick (for viewers; the world never uses it)
  // A tool's (docs/tool.md; for viewers, as force_N): oriented = 1, the torque on the grip about its centre, and the
  // grip's and the proxy's orientations (finger_m and proxy_m are their centres), unit quaternions w, x, y, z. A
  // finger's: 0, zero, and the identity.
  std::uint32_t oriented = 0;
  Vec3 torque_Nm{};
  std::array<double, 4> finger_wxyz{1.0, 0.0, 0.0, 0.0};
  std::array<double, 4> proxy_wxyz{1.0, 0.0, 0.0, 0.0};
  std::uint32_t finger_valid = 0;   // 0 while no device is attached: position coupling must not use finger_m
  std::uint32_t entry_count = 0;
  Vec3 static_impulse_Ns{};         // share of the reaction that went into static geometry (floor, fixed objects)
  // The link's round trip as this endpoint's servo measured it at its newest frame, s: the ticks from the report that
  // frame applied to the frame's arrival, at the nominal tick period (0 when the frame applied the tick just rendered,
  // as in lockstep without delay). The world widens its reach by the finger's travel over it (feature_extractor.h).
  double link_round_trip_s = 0.0;
  std::array<ObjectImpulse, kMaxImpulseEntries> entries{};
};

inline constexpr int kStringCount = 4;  // the desktop SPIDAR's strings, one finger (common/spidar/geometry.h)
// The most strings a device port carries: the grip SPIDAR's eight (common/spidar/grip_geometry.h). A device with fewer
// uses the first of them and leaves the rest zero.
inline constexpr int kMaxDeviceStrings = 8;

// DeviceCommand::flags: the haptic controller renders a world (a world frame has reached its servo). A device may
// show it; a simulated hand playing a script waits for it in real time, so the script does not start before there is
// anything to touch (the processes of a trial start in any order).
inline constexpr std::uint64_t kCommandWorldPresent = 1;

// The first N of a port's string arrays as a device of N strings has them, and back (the rest left as they are).
template <std::size_t N, typename T>
std::array<T, N> first_strings(const std::array<T, kMaxDeviceStrings>& all) {
  static_assert(N <= kMaxDeviceStrings);
  std::array<T, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = all[i];
  return out;
}
template <std::size_t N, typename T>
void set_first_strings(const std::array<T, N>& some, std::array<T, kMaxDeviceStrings>& all) {
  static_assert(N <= kMaxDeviceStrings);
  for (std::size_t i = 0; i < N; ++i) all[i] = some[i];
}

// Haptic → device: the tensions to command (docs/architecture.md §1.2 step 6).
struct DeviceCommand {
  std::uint64_t tick = 0;
  std::uint64_t haptic_session = 0;
  std::array<double, kMaxDeviceStrings> tension_N{};
  std::uint64_t flags = 0;  // kCommand* bits; others are reserved and ignored
};

// Device → haptic: the encoder readings.
struct DeviceState {
  std::uint64_t tick = 0;            // device tick; in lockstep equal to the haptic tick it answers
  std::uint64_t device_session = 0;  // changes on each attach
  std::array<std::int64_t, kMaxDeviceStrings> encoder_counts{};
};

// Copy a frame or report by its used part: the header, then the planes (entries) below its count, clamped to the
// capacity. What `to` held beyond that count is reset to a value-initialised Plane (ObjectImpulse), so a destination
// whose unused slots were value-initialised keeps them so, as the transports' decoders leave them. A whole frame is
// ~56 KB and a report ~7 KB while a trial touches a few planes: this costs what is used, not the capacity. Never
// allocates or throws (the 1 kHz path copies reports). `from` and `to` may be the same object.
void copy_used(const PlaneFrame& from, PlaneFrame& to) noexcept;
void copy_used(const HapticReport& from, HapticReport& to) noexcept;

static_assert(std::is_trivially_copyable_v<Plane>);
static_assert(std::is_trivially_copyable_v<PlaneFrame>);
static_assert(std::is_trivially_copyable_v<ObjectImpulse>);
static_assert(std::is_trivially_copyable_v<HapticReport>);
static_assert(std::is_trivially_copyable_v<DeviceCommand>);
static_assert(std::is_trivially_copyable_v<DeviceState>);

}  // namespace impetus
