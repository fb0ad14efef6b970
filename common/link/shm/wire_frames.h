// SPDX-License-Identifier: Apache-2.0
#pragma once
// The shared-memory transport's encoding of the contract frames (common/contract/frames.h): the same fields in a
// fixed layout of whole 64-bit words, every frame sealed with a checksum. A plane frame and a haptic report carry
// their checksum first and count only their used bytes (the header and the counted planes or entries, used_bytes()):
// those alone are sealed, written to the channel and read back, so a report of one touched object costs ~0.3 KB a
// tick, not its 7 KB capacity. The two small device frames are sealed whole, checksum last.
//
// Writers encode() a contract frame into its wire form (which seals it); readers decode(), which accepts a frame only
// if its checksum matches and its content is usable (counts within capacity, numbers finite, normals unit, friction
// ordered), and otherwise names the reason. Nothing outside the transport sees these types.
//
// Changing any struct here changes the shared-memory layout: bump kLayoutVersion in segment.h.

#include "common/contract/frames.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace impetus {
namespace wire {

struct LocalContact {
  Vec3 normal{};
  double friction = 0.0;
  Vec3 other_velocity_mps{};
  double other_inverse_mass_per_kg = 0.0;
  std::uint32_t flags = 0;
  std::uint32_t reserved = 0;  // keeps the layout in whole 64-bit words (checksum)
  double gap_m = 0.0;
};

struct Plane {
  std::int32_t object_id = -1;
  std::uint32_t flags = 0;
  Vec3 point_m{};
  Vec3 normal{};
  Vec3 com_m{};
  Vec3 velocity_mps{};
  Vec3 angular_velocity_radps{};
  double static_friction = 0.0;
  double dynamic_friction = 0.0;
  double extent_m = 0.0;
  double yield_force_N = 0.0;
  double yield_depth_mpNs = 0.0;
  double yield_radius_m = 0.0;
  double yield_room_m = 0.0;
  double yield_compliance_mpN = 0.0;
  Shape shape;
  Vec3 body_axis_x{};
  Vec3 body_axis_y{};
  double inverse_mass_per_kg = 0.0;
  std::array<double, 9> inverse_inertia_world{};
  std::uint32_t local_contact_count = 0;
  std::uint32_t reserved = 0;
  std::array<LocalContact, kMaxLocalContacts> local_contacts{};
};

struct DentPatch {
  std::int32_t object_id = -1;
  std::uint32_t reserved = 0;
  Vec3 origin_m{};
  Vec3 axis_x{};
  Vec3 axis_y{};
  double spacing_m = 0.0;
  std::array<double, kDentPatchSide * kDentPatchSide> height_m{};
};

struct PlaneFrame {
  std::uint64_t checksum = 0;  // frame_checksum() of the used bytes after it; set by encode()
  std::uint64_t frame_index = 0;
  std::uint64_t world_session = 0;
  EndpointId endpoint = 0;
  std::uint32_t reserved = 0;
  std::uint64_t report_tick_applied = 0;
  std::uint64_t report_session_applied = 0;
  double world_time_s = 0.0;
  double world_period_s = 0.0;
  Coupling coupling = Coupling::impulse;
  std::uint32_t plane_count = 0;
  double stiffness_Npm = 0.0;
  double damping_Nspm = 0.0;
  Vec3 gravity_mps2{};
  double world_substep_s = 0.0;
  double reach_radius_m = 0.0;
  std::uint32_t port_layer = 0;
  std::uint32_t reserved_port = 0;
  double port_returned_J = 0.0;
  DentPatch dent_patch;
  std::array<Plane, kMaxPlanes> planes{};  // the first plane_count are used
};

struct ObjectImpulse {
  std::int32_t object_id = -1;
  std::uint32_t epoch = 0;
  Vec3 impulse_Ns{};
  Vec3 angular_impulse_Nms{};
  Vec3 impulse_moment_Nss{};
  Vec3 angular_impulse_moment_Nmss{};
  double hand_input_J = 0.0;
  double press_Ns = 0.0;
  Vec3 press_point_Nsm{};
  std::array<double, 6> press_point2_Nsm2{};
  std::uint64_t last_tick = 0;
};

struct HapticReport {
  std::uint64_t checksum = 0;  // frame_checksum() of the used bytes after it; set by encode()
  std::uint64_t tick = 0;
  std::uint64_t haptic_session = 0;
  EndpointId endpoint = 0;
  std::uint32_t reserved = 0;
  std::uint64_t world_session = 0;
  double haptic_time_s = 0.0;
  Vec3 finger_m{};
  Vec3 finger_velocity_mps{};
  Vec3 proxy_m{};
  Vec3 force_N{};
  std::uint32_t oriented = 0;
  std::uint32_t reserved_oriented = 0;
  Vec3 torque_Nm{};
  std::array<double, 4> finger_wxyz{};
  std::array<double, 4> proxy_wxyz{};
  std::uint32_t finger_valid = 0;
  std::uint32_t entry_count = 0;
  Vec3 static_impulse_Ns{};
  double link_round_trip_s = 0.0;
  std::array<ObjectImpulse, kMaxImpulseEntries> entries{};  // the first entry_count are used
};

struct DeviceCommand {
  std::uint64_t tick = 0;
  std::uint64_t haptic_session = 0;
  std::array<double, kMaxDeviceStrings> tension_N{};
  std::uint64_t flags = 0;
  std::uint64_t checksum = 0;
};

struct DeviceState {
  std::uint64_t tick = 0;
  std::uint64_t device_session = 0;
  std::array<std::int64_t, kMaxDeviceStrings> encoder_counts{};
  std::uint64_t checksum = 0;
};

static_assert(std::is_trivially_copyable_v<PlaneFrame>);
static_assert(std::is_trivially_copyable_v<HapticReport>);
static_assert(std::is_trivially_copyable_v<DeviceCommand>);
static_assert(std::is_trivially_copyable_v<DeviceState>);

}  // namespace wire

// Why a reader rejected a frame; ok means accepted.
enum class FrameError : std::uint32_t {
  ok = 0,
  checksum,
  count_out_of_range,
  not_finite,
  normal_not_unit,
  bad_period,
  bad_coupling,
  bad_friction,
  bad_reach,
  bad_mass,
  bad_shape,
  bad_yield,
  bad_port,
  bad_gap,
};
const char* to_string(FrameError error);

// The bytes of a frame that carry it: a plane frame's or report's header and counted planes or entries (a count over
// capacity is taken as the capacity; validate() rejects it), a device frame whole.
std::size_t used_bytes(const wire::PlaneFrame& frame);
std::size_t used_bytes(const wire::HapticReport& report);
std::size_t used_bytes(const wire::DeviceCommand& command);
std::size_t used_bytes(const wire::DeviceState& state);

// Checksums cover the used bytes after the checksum field (plane frame, report) or every byte before it (device
// frames).
std::uint64_t frame_checksum(const wire::PlaneFrame& frame);
std::uint64_t frame_checksum(const wire::HapticReport& report);
std::uint64_t frame_checksum(const wire::DeviceCommand& command);
std::uint64_t frame_checksum(const wire::DeviceState& state);

// Checksum and content checks of a received frame (what decode() runs first).
FrameError validate(const wire::PlaneFrame& frame);
FrameError validate(const wire::HapticReport& report);
FrameError validate(const wire::DeviceCommand& command);
FrameError validate(const wire::DeviceState& state);

// Contract → wire, sealed. Only the used bytes are written; entries beyond the count keep what they held. Allocation-free.
void encode(const PlaneFrame& frame, wire::PlaneFrame& out);
void encode(const HapticReport& report, wire::HapticReport& out);
void encode(const DeviceCommand& command, wire::DeviceCommand& out);
void encode(const DeviceState& state, wire::DeviceState& out);

// Wire → contract: validate(), then copy. On error `out` is left unchanged. Allocation-free.
FrameError decode(const wire::PlaneFrame& in, PlaneFrame& out);
FrameError decode(const wire::HapticReport& in, HapticReport& out);
FrameError decode(const wire::DeviceCommand& in, DeviceCommand& out);
FrameError decode(const wire::DeviceState& in, DeviceState& out);

}  // namespace impetus
