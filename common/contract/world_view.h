// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a world shows its viewers (docs/architecture.md §1, paper §6.1 "graphics"): the scene's shapes once, and after
// every world step a snapshot of every body's pose and of each endpoint's finger, proxy, force and active planes. Plain
// data of fixed capacity, SI units, world frame (right-handed, z up). Publishing it never waits on a viewer.

#include "common/contract/frames.h"
#include "common/contract/vec3.h"
#include "common/runtime/loop_stats.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

namespace impetus {

// The largest scene a viewer can show. A shipped scene has at most a few hundred bodies; 2048 leaves room for the
// 2000-body scenes the viewer's frame rate is measured on. Larger scenes run, and their viewers show the first 2048.
inline constexpr std::uint32_t kMaxViewBodies = 2048;
inline constexpr std::uint32_t kMaxViewEndpoints = 8;    // the world serves up to 8 endpoints (docs/architecture.md §1)
inline constexpr std::uint32_t kMaxViewPlanes = 16;      // planes drawn per endpoint: those nearest the finger
inline constexpr std::uint32_t kMaxViewNameBytes = 48;   // a body's name, NUL-terminated, cut to fit

struct ViewBodyInfo {
  Shape shape;  // common/shape/shape_descriptor.h
  std::uint32_t dynamic = 0;
  std::uint32_t reserved = 0;
  std::array<char, kMaxViewNameBytes> name{};
};

// Written once when the world starts; a restarted world writes its own.
struct ViewScene {
  std::uint64_t world_session = 0;  // the world this describes (PlaneFrame::world_session)
  Coupling coupling = Coupling::impulse;
  std::uint32_t floor_present = 0;
  double floor_height_m = 0.0;
  double world_rate_hz = 0.0;
  std::uint32_t body_count = 0;  // <= kMaxViewBodies
  std::uint32_t reserved = 0;
  std::array<ViewBodyInfo, kMaxViewBodies> bodies{};
};

struct ViewBodyPose {
  Vec3 position_m{};
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};  // unit quaternion, body → world
};

struct ViewPlane {
  Vec3 point_m{};
  Vec3 normal{};  // unit, out of the object
};

struct ViewEndpoint {
  EndpointId endpoint = 0;
  std::uint32_t finger_valid = 0;
  Vec3 finger_m{};
  Vec3 proxy_m{};
  Vec3 force_N{};  // on the finger, at the report the world took for this step
  // A tool's (HapticReport): oriented = 1, the torque on the grip, the grip's (finger's) and the proxy's orientations,
  // unit.
  std::uint32_t oriented = 0;
  std::uint32_t reserved_oriented = 0;
  Vec3 torque_Nm{};
  std::array<double, 4> finger_wxyz{1.0, 0.0, 0.0, 0.0};
  std::array<double, 4> proxy_wxyz{1.0, 0.0, 0.0, 0.0};
  std::uint32_t plane_count = 0;  // <= kMaxViewPlanes
  std::uint32_t reserved = 0;
  std::array<ViewPlane, kMaxViewPlanes> planes{};
};

// The dent in a deformable object's top face (world_manager/deform/deformable_surface.h), to draw it: depths below the
// face at columns × rows points of the object's body frame, point (c, r) at (x0 + c·dx, y0 + r·dy) on the face,
// row-major (r·columns + c), the face bilinear between them. The points cover the dented cells, one per cell while
// they fit, further apart beyond; outside them the face is undented. 32 × 32 (4 KB, sent with every snapshot): a
// press at 1 mm cells point for point, a 6 cm stroke at 2 mm.
inline constexpr std::uint32_t kMaxViewDentSide = 32;
struct ViewDent {
  std::int32_t object_id = -1;  // the dented object; -1: none
  std::uint32_t columns = 0;    // 2..kMaxViewDentSide when object_id >= 0
  std::uint32_t rows = 0;
  std::uint32_t reserved = 0;
  std::uint64_t version = 0;    // changes whenever the dent does (a page rebuilds the face only then)
  double x0_m = 0.0;
  double y0_m = 0.0;
  double dx_m = 0.0;            // > 0 when object_id >= 0
  double dy_m = 0.0;
  std::array<float, kMaxViewDentSide * kMaxViewDentSide> depth_m{};  // ≥ 0
};

// After world step i. Bodies come last so a transport can send only the first body_count of them.
struct WorldSnapshot {
  std::uint64_t world_session = 0;
  std::uint64_t frame_index = 0;  // i, as in PlaneFrame
  double world_time_s = 0.0;      // at the end of step i
  double world_period_s = 0.0;
  LoopStats world_stats{};
  LoopStats haptic_stats{};       // the attached haptic controller's, as last published (zero if none)
  std::uint32_t endpoint_count = 0;  // <= kMaxViewEndpoints
  std::uint32_t body_count = 0;      // <= kMaxViewBodies; equals the scene's
  std::array<ViewEndpoint, kMaxViewEndpoints> endpoints{};
  ViewDent dent{};  // the first deformable object with a dent
  std::array<ViewBodyPose, kMaxViewBodies> bodies{};

  // Bytes of this struct that carry the snapshot: the header, endpoints, dent and the first body_count bodies.
  std::size_t used_bytes() const;
};

static_assert(std::is_trivially_copyable_v<ViewScene>);
static_assert(std::is_trivially_copyable_v<WorldSnapshot>);

inline std::size_t WorldSnapshot::used_bytes() const {
  const std::uint32_t bodies_used = body_count < kMaxViewBodies ? body_count : kMaxViewBodies;
  return offsetof(WorldSnapshot, bodies) + bodies_used * sizeof(ViewBodyPose);
}

// The world's end of the view link: never blocks, never fails the world (a transport that cannot publish drops it).
class WorldViewPublisher {
 public:
  virtual ~WorldViewPublisher() = default;
  virtual void publish_scene(const ViewScene& scene) = 0;
  virtual void publish_snapshot(const WorldSnapshot& snapshot) = 0;
};

// A viewer's end of the view link (one per viewer thread; not thread-safe).
class WorldViewReader {
 public:
  virtual ~WorldViewReader() = default;
  // The scene if it was (re)published since the last call and passed scene_problem(); false otherwise.
  virtual bool read_scene(ViewScene& out) = 0;
  // The newest snapshot if new since the last call and valid; false otherwise. Invalid ones are counted.
  virtual bool read_snapshot(WorldSnapshot& out) = 0;
  // False once the world this reader follows has exited: open another to follow a restarted world. A transport
  // that follows whichever world publishes (DDS) says true.
  virtual bool world_alive() const = 0;
  virtual std::uint64_t rejected() const = 0;
  // Where it reads from, for messages.
  virtual const std::string& name() const = 0;
};

// Checks what a viewer read (it cannot trust a segment another process writes): counts within capacity, numbers
// finite, quaternions and normals of unit length within 1e-6. Returns "" if usable, else the first problem.
const char* snapshot_problem(const WorldSnapshot& snapshot);
const char* scene_problem(const ViewScene& scene);

}  // namespace impetus
