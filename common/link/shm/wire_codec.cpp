// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/wire_frames.h"
#include "common/shape/shape.h"

#include "common/link/frame_fields.h"

#include <algorithm>

#include <cmath>
#include <cstddef>
#include <cstring>

namespace impetus {
namespace {

// A normal is accepted as unit if | |n| − 1 | is below this. Writers normalise in double precision (error ~1e-16);
// the slack admits normals that went through a float round trip or an interpolation, and rejects garbage.
constexpr double kUnitNormalTolerance = 1e-6;

// Mixes the 64-bit words of bytes [begin, end) of a frame, and the length. Not cryptographic: it only has to make a
// torn or scribbled frame (random bytes, half of two frames) fail with overwhelming probability, cheaply enough for a
// 1 kHz writer.
template <class Frame>
std::uint64_t checksum_words(const Frame& frame, std::size_t begin, std::size_t end) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(&frame);
  std::uint64_t hash = 0x9E3779B97F4A7C15ull ^ (end - begin);
  for (std::size_t offset = begin; offset < end; offset += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + offset, 8);
    hash = (hash ^ word) * 0xBF58476D1CE4E5B9ull;
    hash ^= hash >> 31;
  }
  return hash;
}

// A frame sealed at its head: the used bytes after the checksum.
template <class Frame>
std::uint64_t checksum_after_head(const Frame& frame) {
  static_assert(offsetof(Frame, checksum) == 0, "the checksum leads the frame");
  static_assert(sizeof(Frame) % 8 == 0, "whole 64-bit words");
  return checksum_words(frame, sizeof(frame.checksum), used_bytes(frame));
}

// A frame sealed at its tail: every byte before the checksum.
template <class Frame>
std::uint64_t checksum_before_tail(const Frame& frame) {
  constexpr std::size_t covered = offsetof(Frame, checksum);
  static_assert(covered % 8 == 0, "checksum must follow whole 64-bit words");
  return checksum_words(frame, 0, covered);
}

bool finite(double value) { return std::isfinite(value); }

struct CopyInto {
  template <class From, class To>
  void operator()(const From& from, To& to) const {
    to = from;
  }
};

template <class Frame>
void seal(Frame& frame) {
  frame.checksum = frame_checksum(frame);
}

}  // namespace

const char* to_string(FrameError error) {
  switch (error) {
    case FrameError::ok: return "ok";
    case FrameError::checksum: return "checksum mismatch";
    case FrameError::count_out_of_range: return "count out of range";
    case FrameError::not_finite: return "non-finite number";
    case FrameError::normal_not_unit: return "normal or orientation is not of unit length";
    case FrameError::bad_period: return "world period is not positive, or a round trip is negative";
    case FrameError::bad_coupling: return "unknown coupling";
    case FrameError::bad_friction: return "friction coefficient negative or dynamic > static";
    case FrameError::bad_reach: return "reach radius or plane extent is negative";
    case FrameError::bad_yield:
      return "a deformable plane's yield force, depth rate, pad radius or room is negative, or its patch is malformed";
    case FrameError::bad_mass: return "a local contact's inverse mass is negative";
    case FrameError::bad_shape: return "a plane's shape is unknown or out of range, or its body axes not orthonormal";
    case FrameError::bad_port: return "the passivity layer's flag is not 0 or 1, or its returned energy is negative";
    case FrameError::bad_gap: return "a local contact's gap is negative";
  }
  return "unknown frame error";
}

std::size_t used_bytes(const wire::PlaneFrame& frame) {
  return offsetof(wire::PlaneFrame, planes) + std::min(frame.plane_count, kMaxPlanes) * sizeof(wire::Plane);
}
std::size_t used_bytes(const wire::HapticReport& report) {
  return offsetof(wire::HapticReport, entries) +
         std::min(report.entry_count, kMaxImpulseEntries) * sizeof(wire::ObjectImpulse);
}
std::size_t used_bytes(const wire::DeviceCommand&) { return sizeof(wire::DeviceCommand); }
std::size_t used_bytes(const wire::DeviceState&) { return sizeof(wire::DeviceState); }

std::uint64_t frame_checksum(const wire::PlaneFrame& frame) { return checksum_after_head(frame); }
std::uint64_t frame_checksum(const wire::HapticReport& report) { return checksum_after_head(report); }
std::uint64_t frame_checksum(const wire::DeviceCommand& command) { return checksum_before_tail(command); }
std::uint64_t frame_checksum(const wire::DeviceState& state) { return checksum_before_tail(state); }

FrameError validate(const wire::PlaneFrame& frame) {
  if (frame.checksum != frame_checksum(frame)) return FrameError::checksum;
  if (frame.plane_count > kMaxPlanes) return FrameError::count_out_of_range;
  if (!finite(frame.world_time_s) || !finite(frame.stiffness_Npm) || !finite(frame.damping_Nspm) ||
      !all_finite(frame.gravity_mps2) || !finite(frame.world_substep_s) || !finite(frame.reach_radius_m)) {
    return FrameError::not_finite;
  }
  if (!(frame.world_period_s > 0.0) || !finite(frame.world_period_s)) return FrameError::bad_period;
  if (frame.world_substep_s < 0.0) return FrameError::bad_period;
  if (frame.reach_radius_m < 0.0) return FrameError::bad_reach;
  if (frame.port_layer > 1 || !(frame.port_returned_J >= 0.0) || !finite(frame.port_returned_J)) {
    return FrameError::bad_port;
  }
  if (frame.dent_patch.object_id >= 0) {
    const wire::DentPatch& patch = frame.dent_patch;
    if (!all_finite(patch.origin_m) || !all_finite(patch.axis_x) || !all_finite(patch.axis_y) ||
        !finite(patch.spacing_m)) {
      return FrameError::not_finite;
    }
    for (double height : patch.height_m) {
      if (!finite(height)) return FrameError::not_finite;
    }
    const auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    if (!(patch.spacing_m > 0.0) || std::fabs(dot(patch.axis_x, patch.axis_x) - 1.0) > kUnitNormalTolerance ||
        std::fabs(dot(patch.axis_y, patch.axis_y) - 1.0) > kUnitNormalTolerance ||
        std::fabs(dot(patch.axis_x, patch.axis_y)) > kUnitNormalTolerance) {
      return FrameError::bad_yield;
    }
  }
  if (static_cast<std::uint32_t>(frame.coupling) > static_cast<std::uint32_t>(Coupling::local)) {
    return FrameError::bad_coupling;
  }
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    const wire::Plane& plane = frame.planes[k];
    if (!all_finite(plane.point_m) || !all_finite(plane.normal) || !all_finite(plane.com_m) ||
        !all_finite(plane.velocity_mps) || !all_finite(plane.angular_velocity_radps) ||
        !finite(plane.static_friction) || !finite(plane.dynamic_friction) || !finite(plane.inverse_mass_per_kg) ||
        !finite(plane.extent_m) || !finite(plane.yield_force_N) || !finite(plane.yield_depth_mpNs) ||
        !finite(plane.yield_radius_m) || !finite(plane.yield_room_m) || !finite(plane.yield_compliance_mpN)) {
      return FrameError::not_finite;
    }
    if (plane.extent_m < 0.0) return FrameError::bad_reach;
    if (plane.yield_force_N < 0.0 || plane.yield_depth_mpNs < 0.0 || plane.yield_radius_m < 0.0 ||
        plane.yield_room_m < 0.0 || plane.yield_compliance_mpN < 0.0) {
      return FrameError::bad_yield;
    }
    if (!all_finite(plane.body_axis_x) || !all_finite(plane.body_axis_y) || !all_finite(plane.shape.box_size_m) ||
        !finite(plane.shape.radius_m) || !finite(plane.shape.length_m)) {
      return FrameError::not_finite;
    }
    if (shape_problem(plane.shape) != nullptr) return FrameError::bad_shape;
    if (traits(plane.shape.kind).carries_axes) {
      const auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
      if (std::fabs(dot(plane.body_axis_x, plane.body_axis_x) - 1.0) > kUnitNormalTolerance ||
          std::fabs(dot(plane.body_axis_y, plane.body_axis_y) - 1.0) > kUnitNormalTolerance ||
          std::fabs(dot(plane.body_axis_x, plane.body_axis_y)) > kUnitNormalTolerance) {
        return FrameError::bad_shape;
      }
    }
    for (double value : plane.inverse_inertia_world) {
      if (!finite(value)) return FrameError::not_finite;
    }
    if (plane.local_contact_count > kMaxLocalContacts) return FrameError::count_out_of_range;
    for (std::uint32_t c = 0; c < plane.local_contact_count; ++c) {
      const wire::LocalContact& contact = plane.local_contacts[c];
      if (!all_finite(contact.normal) || !finite(contact.friction) || !all_finite(contact.other_velocity_mps) ||
          !finite(contact.other_inverse_mass_per_kg) || !finite(contact.gap_m)) {
        return FrameError::not_finite;
      }
      if (contact.other_inverse_mass_per_kg < 0.0) return FrameError::bad_mass;
      if (contact.gap_m < 0.0) return FrameError::bad_gap;
      const double length = std::sqrt(contact.normal[0] * contact.normal[0] + contact.normal[1] * contact.normal[1] +
                                      contact.normal[2] * contact.normal[2]);
      if (std::fabs(length - 1.0) > kUnitNormalTolerance) return FrameError::normal_not_unit;
      if (contact.friction < 0.0) return FrameError::bad_friction;
    }
    const double norm = std::sqrt(plane.normal[0] * plane.normal[0] + plane.normal[1] * plane.normal[1] +
                                  plane.normal[2] * plane.normal[2]);
    if (std::fabs(norm - 1.0) > kUnitNormalTolerance) return FrameError::normal_not_unit;
    if (plane.static_friction < 0.0 || plane.dynamic_friction < 0.0 ||
        plane.dynamic_friction > plane.static_friction) {
      return FrameError::bad_friction;
    }
  }
  return FrameError::ok;
}

FrameError validate(const wire::HapticReport& report) {
  if (report.checksum != frame_checksum(report)) return FrameError::checksum;
  if (report.entry_count > kMaxImpulseEntries) return FrameError::count_out_of_range;
  if (!finite(report.haptic_time_s) || !all_finite(report.finger_m) || !all_finite(report.finger_velocity_mps) ||
      !all_finite(report.proxy_m) || !all_finite(report.force_N) || !all_finite(report.torque_Nm) ||
      !all_finite(report.static_impulse_Ns) || !finite(report.link_round_trip_s)) {
    return FrameError::not_finite;
  }
  // The grip's and the proxy's orientations must be unit quaternions, to the normals' tolerance.
  for (const auto* q : {&report.finger_wxyz, &report.proxy_wxyz}) {
    const double norm = std::sqrt((*q)[0] * (*q)[0] + (*q)[1] * (*q)[1] + (*q)[2] * (*q)[2] + (*q)[3] * (*q)[3]);
    if (!(std::fabs(norm - 1.0) <= kUnitNormalTolerance)) return FrameError::normal_not_unit;
  }
  if (report.link_round_trip_s < 0.0) return FrameError::bad_period;
  if (report.oriented > 1) return FrameError::count_out_of_range;  // a flag: 0 or 1
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    const wire::ObjectImpulse& entry = report.entries[k];
    if (!all_finite(entry.impulse_Ns) || !all_finite(entry.angular_impulse_Nms) ||
        !all_finite(entry.impulse_moment_Nss) || !all_finite(entry.angular_impulse_moment_Nmss) ||
        !finite(entry.hand_input_J) || !finite(entry.press_Ns) || !all_finite(entry.press_point_Nsm) ||
        !std::all_of(entry.press_point2_Nsm2.begin(), entry.press_point2_Nsm2.end(), finite)) {
      return FrameError::not_finite;
    }
  }
  return FrameError::ok;
}

FrameError validate(const wire::DeviceCommand& command) {
  if (command.checksum != frame_checksum(command)) return FrameError::checksum;
  for (double tension : command.tension_N) {
    if (!finite(tension)) return FrameError::not_finite;
  }
  return FrameError::ok;
}

FrameError validate(const wire::DeviceState& state) {
  if (state.checksum != frame_checksum(state)) return FrameError::checksum;
  return FrameError::ok;
}

// Encoding copies the counted slots only: the rest is not part of the frame (used_bytes()), never sealed, sent or read.
// A count over capacity is copied as it is, so the reader rejects the frame rather than receive a truncated one.
void encode(const PlaneFrame& frame, wire::PlaneFrame& out) {
  fields::visit_frame_header(frame, out, CopyInto{});
  const std::uint32_t count = std::min(frame.plane_count, kMaxPlanes);
  for (std::size_t k = 0; k < count; ++k) fields::visit_plane(frame.planes[k], out.planes[k], CopyInto{});
  seal(out);
}

void encode(const HapticReport& report, wire::HapticReport& out) {
  fields::visit_report_header(report, out, CopyInto{});
  const std::uint32_t count = std::min(report.entry_count, kMaxImpulseEntries);
  for (std::size_t k = 0; k < count; ++k) fields::visit_entry(report.entries[k], out.entries[k], CopyInto{});
  seal(out);
}

void encode(const DeviceCommand& command, wire::DeviceCommand& out) {
  out.tick = command.tick;
  out.haptic_session = command.haptic_session;
  out.tension_N = command.tension_N;
  out.flags = command.flags;
  seal(out);
}

void encode(const DeviceState& state, wire::DeviceState& out) {
  out.tick = state.tick;
  out.device_session = state.device_session;
  out.encoder_counts = state.encoder_counts;
  seal(out);
}

// Decoding copies the counted slots only; the slots `out` used beyond the new count are reset, so nothing unvalidated
// reaches the contract frame and, as with copy_used (frames.h), a value-initialised frame's unused slots stay so. The
// cost follows the counts, not the capacity.
FrameError decode(const wire::PlaneFrame& in, PlaneFrame& out) {
  const FrameError error = validate(in);
  if (error != FrameError::ok) return error;
  const std::uint32_t used_before = std::min(out.plane_count, kMaxPlanes);
  fields::visit_frame_header(in, out, CopyInto{});
  for (std::size_t k = 0; k < in.plane_count; ++k) {
    fields::visit_plane(in.planes[k], out.planes[k], CopyInto{});
    for (std::size_t c = in.planes[k].local_contact_count; c < kMaxLocalContacts; ++c) {
      out.planes[k].local_contacts[c] = LocalContact{};
    }
  }
  for (std::size_t k = in.plane_count; k < used_before; ++k) out.planes[k] = Plane{};
  return FrameError::ok;
}

FrameError decode(const wire::HapticReport& in, HapticReport& out) {
  const FrameError error = validate(in);
  if (error != FrameError::ok) return error;
  const std::uint32_t used_before = std::min(out.entry_count, kMaxImpulseEntries);
  fields::visit_report_header(in, out, CopyInto{});
  for (std::size_t k = 0; k < in.entry_count; ++k) fields::visit_entry(in.entries[k], out.entries[k], CopyInto{});
  for (std::size_t k = in.entry_count; k < used_before; ++k) out.entries[k] = ObjectImpulse{};
  return FrameError::ok;
}

FrameError decode(const wire::DeviceCommand& in, DeviceCommand& out) {
  const FrameError error = validate(in);
  if (error != FrameError::ok) return error;
  out.tick = in.tick;
  out.haptic_session = in.haptic_session;
  out.tension_N = in.tension_N;
  out.flags = in.flags;
  return FrameError::ok;
}

FrameError decode(const wire::DeviceState& in, DeviceState& out) {
  const FrameError error = validate(in);
  if (error != FrameError::ok) return error;
  out.tick = in.tick;
  out.device_session = in.device_session;
  out.encoder_counts = in.encoder_counts;
  return FrameError::ok;
}

}  // namespace impetus
