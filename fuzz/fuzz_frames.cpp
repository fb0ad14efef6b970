// SPDX-License-Identifier: Apache-2.0
// Fuzz target: the shared-memory transport's frame decoding, the gate every reader of the world link and the device
// port passes frames through.
// Input: one selector byte, then the frame's bytes (short input: the rest stays zero, as in a fresh segment).
//   selector bits 0-1: PlaneFrame, HapticReport, DeviceCommand or DeviceState
//   selector bit 2:    seal the frame first. Random bytes almost never carry a valid checksum, so without this the
//                      fuzzer would only ever exercise the checksum test; sealed frames reach every later check.
// decode() must not crash on any bytes, and when it accepts a frame, everything a reader takes from the decoded
// contract frame must be usable: counts within capacity, numbers finite, normals unit, friction coefficients ordered,
// period positive. When contract/frames.h gains a field a reader uses, add it to check_accepted below (the fuzzer then
// finds a validate() that forgot it).

#include "common/link/shm/wire_frames.h"
#include "fuzz/fuzz_check.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace {

using namespace impetus;

// Loose compared with validate's 1e-6, so the check flags a broken test rather than restating it.
constexpr double kUnitSlack = 1e-5;

template <class Frame>
Frame frame_from(const std::uint8_t* data, std::size_t size, bool sealed) {
  Frame frame{};
  std::memcpy(&frame, data, size < sizeof(Frame) ? size : sizeof(Frame));
  if (sealed) frame.checksum = frame_checksum(frame);
  return frame;
}

void check_accepted(const PlaneFrame& frame) {
  FUZZ_CHECK(frame.plane_count <= kMaxPlanes);
  FUZZ_CHECK(std::isfinite(frame.world_time_s) && std::isfinite(frame.stiffness_Npm) &&
             std::isfinite(frame.damping_Nspm) && all_finite(frame.gravity_mps2));
  FUZZ_CHECK(std::isfinite(frame.world_period_s) && frame.world_period_s > 0.0);
  FUZZ_CHECK(std::isfinite(frame.reach_radius_m) && frame.reach_radius_m >= 0.0);
  FUZZ_CHECK(frame.port_layer <= 1 && std::isfinite(frame.port_returned_J) && frame.port_returned_J >= 0.0);
  FUZZ_CHECK(frame.coupling == Coupling::impulse || frame.coupling == Coupling::position ||
             frame.coupling == Coupling::local);
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    const Plane& plane = frame.planes[k];
    FUZZ_CHECK(all_finite(plane.point_m) && all_finite(plane.normal) && all_finite(plane.com_m) &&
               all_finite(plane.velocity_mps) && all_finite(plane.angular_velocity_radps));
    FUZZ_CHECK(std::isfinite(plane.inverse_mass_per_kg));
    FUZZ_CHECK(std::isfinite(plane.extent_m) && plane.extent_m >= 0.0);
    FUZZ_CHECK(plane.yield_force_N >= 0.0 && plane.yield_depth_mpNs >= 0.0 && plane.yield_radius_m >= 0.0 &&
               plane.yield_room_m >= 0.0 && plane.yield_compliance_mpN >= 0.0);
    for (double value : plane.inverse_inertia_world) FUZZ_CHECK(std::isfinite(value));
    const double norm = std::hypot(plane.normal[0], plane.normal[1], plane.normal[2]);
    FUZZ_CHECK(std::fabs(norm - 1.0) < kUnitSlack);
    FUZZ_CHECK(std::isfinite(plane.static_friction) && std::isfinite(plane.dynamic_friction));
    FUZZ_CHECK(plane.dynamic_friction >= 0.0 && plane.dynamic_friction <= plane.static_friction);
    FUZZ_CHECK(plane.local_contact_count <= kMaxLocalContacts);
    for (std::uint32_t c = 0; c < plane.local_contact_count; ++c) {
      const LocalContact& contact = plane.local_contacts[c];
      FUZZ_CHECK(all_finite(contact.normal) && std::isfinite(contact.friction) && contact.friction >= 0.0);
      FUZZ_CHECK(std::fabs(std::hypot(contact.normal[0], contact.normal[1], contact.normal[2]) - 1.0) < kUnitSlack);
    }
  }
}

void check_accepted(const HapticReport& report) {
  FUZZ_CHECK(report.entry_count <= kMaxImpulseEntries);
  FUZZ_CHECK(std::isfinite(report.haptic_time_s) && all_finite(report.finger_m) &&
             all_finite(report.finger_velocity_mps) && all_finite(report.proxy_m) &&
             all_finite(report.static_impulse_Ns));
  FUZZ_CHECK(std::isfinite(report.link_round_trip_s) && report.link_round_trip_s >= 0.0);
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    const ObjectImpulse& entry = report.entries[k];
    FUZZ_CHECK(all_finite(entry.impulse_Ns) && all_finite(entry.angular_impulse_Nms) &&
               all_finite(entry.impulse_moment_Nss) && all_finite(entry.angular_impulse_moment_Nmss) &&
               std::isfinite(entry.hand_input_J) && std::isfinite(entry.press_Ns) &&
               all_finite(entry.press_point_Nsm) &&
               std::all_of(entry.press_point2_Nsm2.begin(), entry.press_point2_Nsm2.end(),
                           [](double v) { return std::isfinite(v); }));
  }
}

void check_accepted(const DeviceCommand& command) {
  for (double tension : command.tension_N) FUZZ_CHECK(std::isfinite(tension));
}

void check_accepted(const DeviceState&) {}  // integers only: any encoder count is representable

template <class WireFrame, class Frame>
void run(const std::uint8_t* data, std::size_t size, bool sealed) {
  const WireFrame frame = frame_from<WireFrame>(data, size, sealed);
  static Frame decoded;  // static: a PlaneFrame is too big for the fuzzer's stack
  decoded = Frame{};
  const FrameError error = decode(frame, decoded);
  FUZZ_CHECK(to_string(error) != nullptr);
  if (error == FrameError::ok) {
    FUZZ_CHECK(frame.checksum == frame_checksum(frame));
    check_accepted(decoded);
  }
  // The checksum must cover the frame: a changed byte it covers must be rejected (here byte 8, which every frame's
  // checksum covers: the second word of a frame sealed at its head, the second of one sealed at its tail).
  if (sealed) {
    WireFrame torn = frame;
    reinterpret_cast<unsigned char*>(&torn)[8] ^= 0x01;
    FUZZ_CHECK(validate(torn) == FrameError::checksum);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t selector = data[0];
  const bool sealed = (selector & 0x04) != 0;
  ++data;
  --size;
  switch (selector & 0x03) {
    case 0: run<wire::PlaneFrame, PlaneFrame>(data, size, sealed); break;
    case 1: run<wire::HapticReport, HapticReport>(data, size, sealed); break;
    case 2: run<wire::DeviceCommand, DeviceCommand>(data, size, sealed); break;
    case 3: run<wire::DeviceState, DeviceState>(data, size, sealed); break;
  }
  return 0;
}
