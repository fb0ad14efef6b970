// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/wire_frames.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace impetus {
namespace {

PlaneFrame valid_frame() {
  PlaneFrame frame{};
  frame.frame_index = 3;
  frame.world_period_s = 0.05;
  frame.stiffness_Npm = 2000.0;
  frame.plane_count = 2;
  for (std::uint32_t k = 0; k < 2; ++k) {
    frame.planes[k].object_id = static_cast<std::int32_t>(k);
    frame.planes[k].normal = {0.0, 0.0, 1.0};
    frame.planes[k].static_friction = 0.6;
    frame.planes[k].dynamic_friction = 0.4;
  }
  return frame;
}

template <class Frame>
wire::PlaneFrame encoded(const Frame& frame) {
  wire::PlaneFrame out;
  encode(frame, out);
  return out;
}

FrameError decoded(const wire::PlaneFrame& in) {
  static PlaneFrame out;  // static: a frame is large for the stack of a test
  return decode(in, out);
}

}  // namespace

TEST_CASE("an encoded valid frame decodes to the same frame") {
  const PlaneFrame frame = valid_frame();
  static PlaneFrame copy;
  REQUIRE(decode(encoded(frame), copy) == FrameError::ok);
  CHECK(std::memcmp(&copy, &frame, sizeof frame) == 0);
  HapticReport report{};
  report.entry_count = 1;
  report.endpoint = 3;
  report.entries[0].impulse_Ns = {0.25, -0.5, 1.0};
  wire::HapticReport wire_report;
  encode(report, wire_report);
  static HapticReport report_copy;
  REQUIRE(decode(wire_report, report_copy) == FrameError::ok);
  CHECK(report_copy.endpoint == 3);
  CHECK(report_copy.entries[0].impulse_Ns == report.entries[0].impulse_Ns);
  CHECK(report_copy.oriented == 0);  // a finger's: level
  CHECK(report_copy.proxy_wxyz == std::array<double, 4>{1.0, 0.0, 0.0, 0.0});

  // A tool's: its grip's and proxy's orientations and the torque, whole; an orientation that is not unit, a torque
  // that is not finite, or a flag that is not 0 or 1 is refused.
  report.oriented = 1;
  report.finger_wxyz = {0.6, 0.0, 0.8, 0.0};
  report.proxy_wxyz = {0.8, 0.6, 0.0, 0.0};
  report.torque_Nm = {0.0, -0.04, 0.001};
  encode(report, wire_report);
  REQUIRE(decode(wire_report, report_copy) == FrameError::ok);
  CHECK(report_copy.oriented == 1);
  CHECK(report_copy.finger_wxyz == report.finger_wxyz);
  CHECK(report_copy.proxy_wxyz == report.proxy_wxyz);
  CHECK(report_copy.torque_Nm == report.torque_Nm);
  for (int bad = 0; bad < 3; ++bad) {
    HapticReport broken = report;
    if (bad == 0) broken.proxy_wxyz = {1.0, 0.1, 0.0, 0.0};
    if (bad == 1) broken.torque_Nm[1] = std::numeric_limits<double>::infinity();
    if (bad == 2) broken.oriented = 2;
    encode(broken, wire_report);
    CHECK(decode(wire_report, report_copy) != FrameError::ok);
  }
}

TEST_CASE("frame decoding rejects each kind of bad frame with its reason") {
  auto rejected = [](auto mutate) {
    PlaneFrame frame = valid_frame();
    mutate(frame);
    return decoded(encoded(frame));
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(rejected([](PlaneFrame& f) { f.plane_count = kMaxPlanes + 1; }) == FrameError::count_out_of_range);
  CHECK(rejected([&](PlaneFrame& f) { f.planes[1].point_m[2] = nan; }) == FrameError::not_finite);
  CHECK(rejected([&](PlaneFrame& f) { f.planes[0].velocity_mps[0] = INFINITY; }) == FrameError::not_finite);
  CHECK(rejected([](PlaneFrame& f) { f.planes[0].normal = {0.0, 0.0, 1.01}; }) == FrameError::normal_not_unit);
  CHECK(rejected([](PlaneFrame& f) { f.world_period_s = 0.0; }) == FrameError::bad_period);
  CHECK(rejected([](PlaneFrame& f) { f.coupling = static_cast<Coupling>(9); }) == FrameError::bad_coupling);
  CHECK(rejected([](PlaneFrame& f) { f.planes[0].dynamic_friction = 0.9; }) == FrameError::bad_friction);
  CHECK(rejected([](PlaneFrame& f) { f.reach_radius_m = -0.05; }) == FrameError::bad_reach);
  CHECK(rejected([](PlaneFrame& f) { f.planes[0].yield_force_N = -0.5; }) == FrameError::bad_yield);
  CHECK(rejected([](PlaneFrame& f) {
          f.dent_patch.object_id = 0;
          f.dent_patch.axis_x = {1, 0, 0};
          f.dent_patch.axis_y = {0, 1, 0};
          f.dent_patch.spacing_m = 0.0;  // no spacing
        }) == FrameError::bad_yield);
  CHECK(rejected([&](PlaneFrame& f) {
          f.dent_patch.object_id = 0;
          f.dent_patch.axis_x = {1, 0, 0};
          f.dent_patch.axis_y = {0, 1, 0};
          f.dent_patch.spacing_m = 1e-3;
          f.dent_patch.height_m[7] = nan;
        }) == FrameError::not_finite);
  CHECK(rejected([](PlaneFrame& f) { f.planes[0].yield_depth_mpNs = -1e-3; }) == FrameError::bad_yield);
  CHECK(rejected([&](PlaneFrame& f) { f.planes[0].yield_radius_m = nan; }) == FrameError::not_finite);
  CHECK(rejected([](PlaneFrame& f) {
          f.planes[0].local_contact_count = 1;
          f.planes[0].local_contacts[0].normal = {0, 0, 1};
          f.planes[0].local_contacts[0].other_inverse_mass_per_kg = -1.0;
        }) == FrameError::bad_mass);
  const auto floor_ahead = [](PlaneFrame& f, double gap_m) {
    f.planes[0].local_contact_count = 1;
    f.planes[0].local_contacts[0].normal = {0, 0, 1};
    f.planes[0].local_contacts[0].gap_m = gap_m;
  };
  CHECK(rejected([&](PlaneFrame& f) { floor_ahead(f, 0.02); }) == FrameError::ok);
  CHECK(rejected([&](PlaneFrame& f) { floor_ahead(f, -1e-3); }) == FrameError::bad_gap);
  CHECK(rejected([&](PlaneFrame& f) { floor_ahead(f, nan); }) == FrameError::not_finite);
  CHECK(rejected([&](PlaneFrame& f) { f.reach_radius_m = nan; }) == FrameError::not_finite);
  // A box's plane carries the box: orthonormal axes and sizes within the scene's limits, or the frame is refused.
  const auto box = [](PlaneFrame& f) {
    f.planes[0].shape.kind = ShapeKind::box;
    f.planes[0].shape.box_size_m = {0.05, 0.05, 0.05};
    f.planes[0].body_axis_x = {1.0, 0.0, 0.0};
    f.planes[0].body_axis_y = {0.0, 1.0, 0.0};
  };
  CHECK(rejected(box) == FrameError::ok);
  CHECK(rejected([&](PlaneFrame& f) { box(f); f.planes[0].body_axis_y = {0.0, 0.0, 1.001}; }) == FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) { box(f); f.planes[0].body_axis_y = {0.1, 0.995, 0.0}; }) == FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) { box(f); f.planes[0].shape.box_size_m[1] = 0.0; }) == FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) { box(f); f.planes[0].shape.box_size_m[2] = nan; }) == FrameError::not_finite);
  CHECK(rejected([&](PlaneFrame& f) { box(f); f.planes[0].shape.kind = static_cast<ShapeKind>(99); }) ==
        FrameError::bad_shape);
  // A capsule's likewise, its length between the cap centres may be 0 (a ball), its radius not.
  const auto capsule = [&](PlaneFrame& f) {
    box(f);
    f.planes[0].shape = Shape{};
    f.planes[0].shape.kind = ShapeKind::capsule;
    f.planes[0].shape.radius_m = 0.01;
  };
  CHECK(rejected(capsule) == FrameError::ok);
  CHECK(rejected([&](PlaneFrame& f) { capsule(f); f.planes[0].shape.radius_m = 0.0; }) == FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) { capsule(f); f.planes[0].shape.length_m = -0.01; }) == FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) { capsule(f); f.planes[0].body_axis_x = {0.0, 1.0, 0.0}; }) ==
        FrameError::bad_shape);
  // A cylinder's: a length it must have.
  CHECK(rejected([&](PlaneFrame& f) { capsule(f); f.planes[0].shape.kind = ShapeKind::cylinder; }) ==
        FrameError::bad_shape);
  CHECK(rejected([&](PlaneFrame& f) {
          capsule(f);
          f.planes[0].shape.kind = ShapeKind::cylinder;
          f.planes[0].shape.length_m = 0.06;
        }) == FrameError::ok);
  // A sphere's carries no axes: none are checked.
  CHECK(rejected([&](PlaneFrame& f) {
          capsule(f);
          f.planes[0].shape.kind = ShapeKind::sphere;
          f.planes[0].body_axis_x = {};
          f.planes[0].body_axis_y = {};
        }) == FrameError::ok);
  // Planes past the count are not looked at: garbage there is harmless.
  CHECK(rejected([&](PlaneFrame& f) { f.planes[5].point_m[0] = nan; }) == FrameError::ok);

  wire::PlaneFrame unsealed = encoded(valid_frame());
  unsealed.planes[0].point_m[0] = 0.5;
  CHECK(decoded(unsealed) == FrameError::checksum);
}

TEST_CASE("random bytes written over the used part of a frame are rejected, beyond it they are not part of the frame") {
  std::mt19937_64 random(4);
  const wire::PlaneFrame original = encoded(valid_frame());
  const std::size_t used = used_bytes(original);
  REQUIRE(used < sizeof(original));  // a frame of a few planes in room for kMaxPlanes
  int accepted = 0;
  int scribbled = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    wire::PlaneFrame frame = original;
    auto* bytes = reinterpret_cast<unsigned char*>(&frame);
    const std::size_t start = random() % sizeof(frame);
    const std::size_t length = 1 + random() % 64;
    for (std::size_t k = start; k < std::min(sizeof(frame), start + length); ++k) bytes[k] = random() & 0xFF;
    if (start >= used) {  // only the unused tail: the frame reads as before
      PlaneFrame out;
      REQUIRE(decode(frame, out) == FrameError::ok);
      const wire::PlaneFrame again = encoded(out);  // compared in wire form: the contract struct has padding
      CHECK(std::memcmp(&again, &original, used) == 0);
      continue;
    }
    // Scribbles that happen to leave every used byte unchanged are not corruption.
    if (std::memcmp(&frame, &original, used) == 0) continue;
    ++scribbled;
    if (decoded(frame) == FrameError::ok) ++accepted;
  }
  CHECK(scribbled > 30);
  CHECK(accepted == 0);
}

}  // namespace impetus
