// SPDX-License-Identifier: Apache-2.0
// A deformable surface on the haptic side: the push beyond yield the accumulator reports, and the local yield between
// world frames (haptic_controller/local_yield.h).

#include "haptic_controller/god_object.h"
#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/local_yield.h"
#include "test_support.h"

#include <catch2/catch.hpp>

using namespace impetus;
using Eigen::Vector3d;

namespace {

constexpr std::uint64_t kSession = 5;
constexpr double kYieldForce_N = 0.5;
constexpr double kYieldDepth_mpNs = 0.02;  // 2 cm per N·s beyond yield
constexpr double kPad_m = 0.006;

// The clay's top face at z = 0.03 as the world sends it: deformable, object 0.
Plane clay_plane() {
  Plane plane = test::wire_plane(0, Vector3d(0, 0, 0.03), Vector3d::UnitZ(), false);
  plane.flags |= kPlaneDeformable;
  plane.yield_force_N = kYieldForce_N;
  plane.yield_depth_mpNs = kYieldDepth_mpNs;
  plane.yield_radius_m = kPad_m;
  plane.yield_room_m = 0.02;
  return plane;
}

ContactPlane contact_clay() { return to_contact_plane(clay_plane()); }

ImpulseShare share(double yielding_Ns) {
  ImpulseShare s;
  s.object_id = 0;
  s.yielding_Ns = yielding_Ns;
  return s;
}

}  // namespace

TEST_CASE("a deformable surface gets an entry with the push beyond its yield force, a rigid one the static total") {
  const PlaneSet planes = test::make_set({contact_clay()});
  GodObject god;
  const GodObjectResult& contact = god.solve(planes, Vector3d(0.001, 0.0, 0.029), 1e-3);
  REQUIRE(contact.contact.active_count == 1);
  ImpulseAccumulator accumulator(kSession);
  accumulator.report().haptic_time_s = 2.0;
  accumulator.add(planes, contact.contact, Vector3d(0, 0, 2.0), 1e-3, 1);  // 2 N on the finger for 1 ms
  const HapticReport& report = accumulator.report();
  REQUIRE(report.entry_count == 1);
  CHECK(to_eigen(report.static_impulse_Ns) == Vector3d::Zero());
  const ObjectImpulse& entry = report.entries[0];
  CHECK(entry.impulse_Ns[2] == Approx(-2e-3));
  CHECK(entry.press_Ns == Approx((2.0 - kYieldForce_N) * 1e-3));  // the threshold taken tick by tick
  CHECK(to_eigen(entry.press_point_Nsm).isApprox(entry.press_Ns * contact.contact.proxy_m));
  const Vector3d x_m = contact.contact.proxy_m;
  CHECK(entry.press_point2_Nsm2[0] == Approx(entry.press_Ns * x_m.x() * x_m.x()));
  CHECK(entry.press_point2_Nsm2[2] == Approx(entry.press_Ns * x_m.x() * x_m.z()));
  CHECK(entry.press_point2_Nsm2[5] == Approx(entry.press_Ns * x_m.z() * x_m.z()));
  REQUIRE(accumulator.last_share_count() == 1);
  CHECK(accumulator.last_shares()[0].yielding_Ns == Approx(entry.press_Ns));

  // Below the yield force: an entry, and no push beyond yield.
  accumulator.add(planes, contact.contact, Vector3d(0, 0, 0.4), 1e-3, 2);
  CHECK(report.entries[0].press_Ns == Approx((2.0 - kYieldForce_N) * 1e-3));
  CHECK(accumulator.last_shares()[0].yielding_Ns == 0.0);

  // The same plane without the flag is rigid and static.
  ContactPlane rigid = contact_clay();
  rigid.flags = 0;
  ImpulseAccumulator other(kSession);
  other.add(test::make_set({rigid}), contact.contact, Vector3d(0, 0, 2.0), 1e-3, 1);
  CHECK(other.report().entry_count == 0);
  CHECK(other.report().static_impulse_Ns[2] == Approx(-2e-3));
  // A dynamic rigid body gets its entry, with no press: nothing dents it.
  rigid.flags = kPlaneDynamic;
  ImpulseAccumulator moving(kSession);
  moving.add(test::make_set({rigid}), contact.contact, Vector3d(0, 0, 2.0), 1e-3, 1);
  REQUIRE(moving.report().entry_count == 1);
  CHECK(moving.report().entries[0].press_Ns == 0.0);
  CHECK(moving.last_shares()[0].yielding_Ns == 0.0);
}

TEST_CASE("a deformable plane yields between frames by the pushes the world has not applied, where they were given") {
  PlaneFrame frame = test::make_frame({clay_plane()});
  frame.report_session_applied = kSession;
  frame.report_tick_applied = 10;
  LocalYield yield;
  const Vector3d proxy_m(0.0, 0.0, 0.03);
  for (std::uint64_t tick = 1; tick <= 20; ++tick) {
    const ImpulseShare s = share(1e-3);
    yield.record(tick, proxy_m + Vector3d(tick <= 15 ? 0.0 : 0.003, 0.0, 0.0), &s, 1);
  }
  // A plane that drifted (interpolation) is replaced by the frame's, moved in by the pending pushes: ticks 11–15 at
  // the proxy (weight 1) and 16–20 3 mm away (weight 1 − 0.25 = 0.75).
  PlaneSet planes = test::make_set({contact_clay()});
  planes.planes[0].point_m = Vector3d(0, 0, 0.031);
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  const double expected_m = kYieldDepth_mpNs * (5 * 1e-3 + 5 * 0.75e-3);
  CHECK(planes.planes[0].point_m.z() == Approx(0.03 - expected_m).epsilon(1e-12));
  // Deeper toward the pushes 3 mm along +x, so the surface there falls away and its normal leans to +x: the slope
  // of the pending dent, yield_depth · Σ e_k · 2·(x_k − proxy)/a².
  const double slope = kYieldDepth_mpNs * 5 * 1e-3 * 2.0 * 0.003 / (kPad_m * kPad_m);
  CHECK((planes.planes[0].normal - Vector3d(slope, 0.0, 1.0).normalized()).norm() < 1e-12);

  // A world that applied none of this session's reports has applied none of these pushes.
  frame.report_session_applied = kSession + 1;
  planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  CHECK(planes.planes[0].point_m.z() == Approx(0.03 - kYieldDepth_mpNs * (15 * 1e-3 + 5 * 0.75e-3)).epsilon(1e-12));

  // Applied up to the newest: the frame's surface as sent. Far from the pushes: nothing pending there either.
  frame.report_session_applied = kSession;
  frame.report_tick_applied = 20;
  planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  CHECK(planes.planes[0].point_m.z() == 0.03);
  frame.report_tick_applied = 0;
  planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, proxy_m + Vector3d(0.02, 0, 0), proxy_m + Vector3d(0.02, 0, 0), 0.0, planes);
  CHECK(planes.planes[0].point_m.z() == 0.03);

  // A rigid plane is left alone; a cleared record holds nothing.
  ContactPlane rigid = contact_clay();
  rigid.flags = 0;
  planes = test::make_set({rigid});
  planes.planes[0].point_m.z() = 0.031;
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  CHECK(planes.planes[0].point_m.z() == 0.031);
  yield.clear();
  planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  CHECK(planes.planes[0].point_m.z() == 0.03);
}

TEST_CASE("local yield keeps its newest pushes when more come than it holds, and counts the forgotten") {
  LocalYield yield;
  const ImpulseShare s = share(1e-4);
  const std::uint64_t extra = 7;
  const Vector3d at_m(0, 0, 0.03);
  for (std::uint64_t tick = 1; tick <= LocalYield::kMaxSamples + extra; ++tick) yield.record(tick, at_m, &s, 1);
  CHECK(yield.forgotten() == extra);
  PlaneFrame frame = test::make_frame({clay_plane()});
  PlaneSet planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, at_m, at_m, 0.0, planes);
  CHECK(planes.planes[0].point_m.z() ==
        Approx(0.03 - kYieldDepth_mpNs * 1e-4 * static_cast<double>(LocalYield::kMaxSamples)).epsilon(1e-12));
}

TEST_CASE("a deformable plane is taken again under the proxy from the frame's heights, and as sent beyond them") {
  // A patch of 1 mm samples over the clay's face (z = 0.03), a linear slope of 0.1 along x (a dent's wall).
  PlaneFrame frame = test::make_frame({clay_plane()});
  DentPatch& patch = frame.dent_patch;
  patch.object_id = 0;
  patch.origin_m = {-0.0155, -0.0155, 0.0};
  patch.axis_x = {1.0, 0.0, 0.0};
  patch.axis_y = {0.0, 1.0, 0.0};
  patch.spacing_m = 0.001;
  for (std::uint32_t j = 0; j < kDentPatchSide; ++j) {
    for (std::uint32_t i = 0; i < kDentPatchSide; ++i) patch.height_m[j * kDentPatchSide + i] = 0.03 - 0.1e-3 * i;
  }
  LocalYield yield;
  PlaneSet planes = test::make_set({contact_clay()});
  const Vector3d proxy_m(0.0021, 0.001, 0.03);
  yield.apply(frame, kSession, proxy_m, proxy_m, 0.0, planes);
  const ContactPlane& plane = planes.planes[0];
  // Under the proxy: the height at x = 2.1 mm (17.6 samples in), and the wall's normal, tilted toward +x.
  CHECK(plane.point_m.x() == Approx(0.0021));
  CHECK(plane.point_m.z() == Approx(0.03 - 0.1 * (0.0021 + 0.0155)).epsilon(1e-12));
  CHECK((plane.normal - Vector3d(0.1, 0.0, 1.0).normalized()).norm() < 1e-12);
  // Beyond the patch: the plane the world sent.
  planes = test::make_set({contact_clay()});
  yield.apply(frame, kSession, Vector3d(0.02, 0.0, 0.03), Vector3d(0.02, 0.0, 0.03), 0.0, planes);
  CHECK(planes.planes[0].point_m == Vector3d(0, 0, 0.03));
  CHECK(planes.planes[0].normal == Vector3d::UnitZ());
}
