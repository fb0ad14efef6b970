#include "common/link_types.h"

#include <cmath>
#include <cstddef>
#include <cstring>

namespace impetus {
namespace {

// A normal is accepted as unit if | |n| − 1 | is below this. Writers normalise in double precision (error ~1e-16);
// the slack admits normals that went through a float round trip or an interpolation, and rejects garbage.
constexpr double kUnitNormalTolerance = 1e-6;

// Mixes every 64-bit word before the checksum field. Not cryptographic: it only has to make a torn or scribbled frame
// (random bytes, half of two frames) fail with overwhelming probability, cheaply enough for a 1 kHz writer.
template <class Frame>
std::uint64_t checksum_words(const Frame& frame) {
  constexpr std::size_t covered = offsetof(Frame, checksum);
  static_assert(covered % 8 == 0, "checksum must follow whole 64-bit words");
  const auto* bytes = reinterpret_cast<const unsigned char*>(&frame);
  std::uint64_t hash = 0x9E3779B97F4A7C15ull ^ covered;
  for (std::size_t offset = 0; offset < covered; offset += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + offset, 8);
    hash = (hash ^ word) * 0xBF58476D1CE4E5B9ull;
    hash ^= hash >> 31;
  }
  return hash;
}

bool finite(double value) { return std::isfinite(value); }

}  // namespace

const char* to_string(FrameError error) {
  switch (error) {
    case FrameError::ok: return "ok";
    case FrameError::checksum: return "checksum mismatch";
    case FrameError::count_out_of_range: return "count out of range";
    case FrameError::not_finite: return "non-finite number";
    case FrameError::normal_not_unit: return "normal is not a unit vector";
    case FrameError::bad_period: return "world period is not positive";
    case FrameError::bad_coupling: return "unknown coupling";
    case FrameError::bad_friction: return "friction coefficient negative or dynamic > static";
    case FrameError::bad_reach: return "reach radius or plane extent is negative";
  }
  return "unknown frame error";
}

std::uint64_t frame_checksum(const PlaneFrame& frame) { return checksum_words(frame); }
std::uint64_t frame_checksum(const HapticReport& report) { return checksum_words(report); }
std::uint64_t frame_checksum(const DeviceCommand& command) { return checksum_words(command); }
std::uint64_t frame_checksum(const DeviceState& state) { return checksum_words(state); }

FrameError validate(const PlaneFrame& frame) {
  if (frame.checksum != frame_checksum(frame)) return FrameError::checksum;
  if (frame.plane_count > kMaxPlanes) return FrameError::count_out_of_range;
  if (!finite(frame.world_time_s) || !finite(frame.stiffness_Npm) || !finite(frame.damping_Nspm) ||
      !all_finite(frame.gravity_mps2) || !finite(frame.world_substep_s) || !finite(frame.reach_radius_m)) {
    return FrameError::not_finite;
  }
  if (!(frame.world_period_s > 0.0) || !finite(frame.world_period_s)) return FrameError::bad_period;
  if (frame.world_substep_s < 0.0) return FrameError::bad_period;
  if (frame.reach_radius_m < 0.0) return FrameError::bad_reach;
  if (static_cast<std::uint32_t>(frame.coupling) > static_cast<std::uint32_t>(Coupling::local)) {
    return FrameError::bad_coupling;
  }
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    const Plane& plane = frame.planes[k];
    if (!all_finite(plane.point_m) || !all_finite(plane.normal) || !all_finite(plane.com_m) ||
        !all_finite(plane.velocity_mps) || !all_finite(plane.angular_velocity_radps) ||
        !finite(plane.static_friction) || !finite(plane.dynamic_friction) || !finite(plane.inverse_mass_per_kg) ||
        !finite(plane.extent_m)) {
      return FrameError::not_finite;
    }
    if (plane.extent_m < 0.0) return FrameError::bad_reach;
    for (double value : plane.inverse_inertia_world) {
      if (!finite(value)) return FrameError::not_finite;
    }
    if (plane.local_contact_count > kMaxLocalContacts) return FrameError::count_out_of_range;
    for (std::uint32_t c = 0; c < plane.local_contact_count; ++c) {
      const LocalContact& contact = plane.local_contacts[c];
      if (!all_finite(contact.normal) || !finite(contact.friction)) return FrameError::not_finite;
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

FrameError validate(const HapticReport& report) {
  if (report.checksum != frame_checksum(report)) return FrameError::checksum;
  if (report.entry_count > kMaxImpulseEntries) return FrameError::count_out_of_range;
  if (!finite(report.haptic_time_s) || !all_finite(report.finger_m) || !all_finite(report.finger_velocity_mps) ||
      !all_finite(report.proxy_m) ||
      !all_finite(report.static_impulse_Ns)) {
    return FrameError::not_finite;
  }
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    const ObjectImpulse& entry = report.entries[k];
    if (!all_finite(entry.impulse_Ns) || !all_finite(entry.angular_impulse_Nms) ||
        !all_finite(entry.impulse_moment_Nss) || !all_finite(entry.angular_impulse_moment_Nmss)) {
      return FrameError::not_finite;
    }
  }
  return FrameError::ok;
}

FrameError validate(const DeviceCommand& command) {
  if (command.checksum != frame_checksum(command)) return FrameError::checksum;
  for (double tension : command.tension_N) {
    if (!finite(tension)) return FrameError::not_finite;
  }
  return FrameError::ok;
}

FrameError validate(const DeviceState& state) {
  if (state.checksum != frame_checksum(state)) return FrameError::checksum;
  return FrameError::ok;
}

}  // namespace impetus
