// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/god_object.h"
#include "haptic_controller/impulse_accumulator.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <random>
#include <set>

using namespace impetus;
using impetus::test::make_plane;
using impetus::test::make_set;
using Eigen::Vector3d;

namespace {

constexpr std::uint64_t kSession = 77;

Vector3d sum_of_entries(const HapticReport& report) {
  Vector3d sum = Vector3d::Zero();
  for (std::uint32_t e = 0; e < report.entry_count; ++e) sum += to_eigen(report.entries[e].impulse_Ns);
  return sum;
}

}  // namespace

TEST_CASE("finger pressing down on a cube on the floor: the cube gets the whole vertical push") {
  // Floor (static, id 0) at z = 0; the cube (dynamic, id 1) has its top at z = 0.05 and its com at z = 0.025.
  ContactPlane cube_top = make_plane({0, 0, 0.05}, {0, 0, 1}, 1, true);
  cube_top.com_m = Vector3d(0, 0, 0.025);
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}, 0, false), cube_top});
  GodObject god;
  const Vector3d finger(0.01, 0.0, 0.045);
  const GodObjectResult& contact = god.solve(planes, finger, 1e-3);
  REQUIRE(contact.contact.active_count == 1);
  const Vector3d force_N = 2000.0 * (contact.contact.proxy_m - finger);  // 10 N up on the finger

  ImpulseAccumulator accumulator(kSession);
  accumulator.add(planes, contact.contact, force_N, 1e-3, 1);
  const HapticReport& report = accumulator.report();
  REQUIRE(report.entry_count == 1);
  REQUIRE(report.entries[0].object_id == 1);
  REQUIRE(to_eigen(report.entries[0].impulse_Ns).isApprox(Vector3d(0, 0, -0.01)));
  REQUIRE(to_eigen(report.static_impulse_Ns) == Vector3d::Zero());
  // (contact − com) × J = (0.01, 0, 0.025) × (0, 0, −0.01) = (0, 1e-4, 0)
  REQUIRE(to_eigen(report.entries[0].angular_impulse_Nms).isApprox(Vector3d(0, 1e-4, 0)));
  REQUIRE(report.entries[0].last_tick == 1);
}

TEST_CASE("finger in the corner between a cube's side and the floor: each is pushed along its own normal") {
  const PlaneSet planes =
      make_set({make_plane({0, 0, 0}, {0, 0, 1}, 0, false), make_plane({0, 0, 0}, {1, 0, 0}, 1, true)});
  GodObject god;
  const Vector3d finger(-0.01, 0.0, -0.03);  // 1 cm into the cube's side, 3 cm into the floor
  const GodObjectResult& contact = god.solve(planes, finger, 1e-3);
  REQUIRE(contact.contact.active_count == 2);
  const Vector3d force_N(1.0, 0.0, 3.0);
  ImpulseAccumulator accumulator(kSession);
  accumulator.add(planes, contact.contact, force_N, 1e-3, 1);
  // The cube's side takes the horizontal push, the floor the vertical one: the finger's press on the floor does not
  // push the cube down (sharing the whole vector by multipliers, 1:3, would).
  REQUIRE(to_eigen(accumulator.report().entries[0].impulse_Ns).isApprox(Vector3d(-1e-3, 0, 0)));
  REQUIRE(to_eigen(accumulator.report().static_impulse_Ns).isApprox(Vector3d(0, 0, -3e-3)));
}

TEST_CASE("a force with a part along the surface: the normal parts by plane, the rest by the multipliers") {
  // One plane: friction along x on a face with normal z. The object gets all of it, normal and tangential.
  const PlaneSet one = make_set({make_plane({0, 0, 0}, {0, 0, 1}, 1, true)});
  ProxySolution contact;
  contact.active[contact.active_count++] = {0, 0.004};
  ImpulseAccumulator single(kSession);
  single.add(one, contact, Vector3d(0.5, 0.0, 2.0), 1e-3, 1);
  REQUIRE(to_eigen(single.report().entries[0].impulse_Ns).isApprox(Vector3d(-0.5e-3, 0, -2e-3)));

  // A pull along a normal is never rendered as a pull on that object: the force (−1, 0, 2) against the corner of
  // the floor (z) and a cube's side (x) has a negative x part, which goes to the remainder and is shared by λ.
  const PlaneSet corner =
      make_set({make_plane({0, 0, 0}, {0, 0, 1}, 0, false), make_plane({0, 0, 0}, {1, 0, 0}, 1, true)});
  ProxySolution both;
  both.active[both.active_count++] = {0, 0.003};
  both.active[both.active_count++] = {1, 0.001};
  ImpulseAccumulator accumulator(kSession);
  const Vector3d force_N(-1.0, 0.0, 2.0);
  accumulator.add(corner, both, force_N, 1e-3, 1);
  const Vector3d cube = to_eigen(accumulator.report().entries[0].impulse_Ns);
  const Vector3d floor = to_eigen(accumulator.report().static_impulse_Ns);
  REQUIRE((cube + floor).isApprox(-force_N * 1e-3));  // nothing lost
  REQUIRE(floor.z() == Approx(-2e-3));                 // the floor takes the press
  REQUIRE(cube.isApprox(0.25 * Vector3d(1e-3, 0, 0)));  // the cube a quarter of the sideways remainder
}

TEST_CASE("impulse is conserved across objects: entries + static + evicted + dropped == total rendered") {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> object(0, 99);  // more objects than report entries
  ImpulseAccumulator accumulator(kSession);
  std::uint64_t applied_tick = 0;
  std::set<std::pair<std::int32_t, std::uint32_t>> seen_epochs;
  for (std::uint64_t tick = 1; tick <= 20000; ++tick) {
    if (tick % 50 == 0) {  // the world applies reports now and then, some of them late
      PlaneFrame frame;
      applied_tick = tick - static_cast<std::uint64_t>(25 * (1.0 + u(rng)));
      frame.report_tick_applied = applied_tick;
      frame.report_session_applied = (tick % 1000 == 0) ? kSession + 1 : kSession;  // now and then a stale session
      accumulator.on_plane_frame(frame);
    }
    PlaneSet planes;
    ProxySolution contact;
    contact.proxy_m = Vector3d(u(rng), u(rng), u(rng));
    const int active = static_cast<int>(3.0 * std::abs(u(rng)));
    for (int j = 0; j < active; ++j) {
      const bool dynamic = u(rng) > -0.5;
      planes.planes[planes.count++] = make_plane(Vector3d::Zero(), Vector3d(u(rng), u(rng), 1.0), object(rng), dynamic);
      contact.active[contact.active_count++] = {j, j == 1 ? 0.0 : std::abs(u(rng))};
    }
    const Vector3d force = active > 0 ? Vector3d(10.0 * Vector3d(u(rng), u(rng), u(rng))) : Vector3d(Vector3d::Zero());
    accumulator.add(planes, contact, force, 1e-3 * (1.0 + 0.1 * u(rng)), tick);

    const HapticReport& report = accumulator.report();
    REQUIRE(report.entry_count <= kMaxImpulseEntries);
    for (std::uint32_t e = 0; e < report.entry_count; ++e) {
      seen_epochs.insert({report.entries[e].object_id, report.entries[e].epoch});
    }
    const Vector3d accounted = sum_of_entries(report) + to_eigen(report.static_impulse_Ns) +
                               accumulator.evicted_impulse_Ns() + accumulator.dropped_impulse_Ns();
    REQUIRE((accounted - accumulator.total_impulse_Ns()).norm() < 1e-12);
  }
  REQUIRE(accumulator.evicted_impulse_Ns() != Vector3d::Zero());  // the eviction path ran
  // Every (object, epoch) pair is unique to one allocation: epochs never repeat.
  std::set<std::uint32_t> epochs;
  for (const auto& pair : seen_epochs) REQUIRE(epochs.insert(pair.second).second);
}

TEST_CASE("a full table evicts only entries the world has applied, else counts the share as dropped") {
  ImpulseAccumulator accumulator(kSession);
  ProxySolution contact;
  contact.active[0] = {0, 1.0};
  contact.active_count = 1;
  auto push = [&](std::int32_t id, std::uint64_t tick) {
    const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}, id, true)});
    accumulator.add(planes, contact, Vector3d(0, 0, 1.0), 1e-3, tick);
  };
  for (std::uint32_t id = 0; id < kMaxImpulseEntries; ++id) push(static_cast<std::int32_t>(id), 10 + id);
  REQUIRE(accumulator.report().entry_count == kMaxImpulseEntries);

  push(1000, 100);  // the world has applied nothing: dropped, counted, no crash
  REQUIRE(accumulator.dropped_shares() == 1);
  REQUIRE(accumulator.dropped_impulse_Ns().z() == Approx(-1e-3));

  PlaneFrame frame;
  frame.report_session_applied = kSession;
  frame.report_tick_applied = 10;  // only object 0's entry (last tick 10) is final
  accumulator.on_plane_frame(frame);
  push(1001, 101);
  REQUIRE(accumulator.report().entries[0].object_id == 1001);
  REQUIRE(accumulator.report().entries[0].epoch == kMaxImpulseEntries + 1);
  REQUIRE(accumulator.report().entries[0].impulse_Ns[2] == Approx(-1e-3));
  push(1002, 102);  // nothing else is final
  REQUIRE(accumulator.dropped_shares() == 2);

  frame.report_session_applied = kSession + 1;  // a report of another haptic session proves nothing about ours
  frame.report_tick_applied = 1000;
  accumulator.on_plane_frame(frame);
  push(1003, 103);
  REQUIRE(accumulator.dropped_shares() == 3);
}

TEST_CASE("a frame of a new world session starts the totals afresh, what the old world did not apply is abandoned") {
  ContactPlane cube_top = make_plane({0, 0, 0.05}, {0, 0, 1}, 1, true);
  cube_top.com_m = Vector3d(0, 0, 0.025);
  const PlaneSet planes = make_set({make_plane({0, 0, 0}, {0, 0, 1}, 0, false), cube_top});
  GodObject god;
  const GodObjectResult& contact = god.solve(planes, Vector3d(0.0, 0.0, 0.045), 1e-3);
  const Vector3d force_N(0.0, 0.0, 10.0);

  ImpulseAccumulator accumulator(kSession);
  PlaneFrame frame;
  frame.world_session = 5;
  frame.world_period_s = 0.05;
  accumulator.on_plane_frame(frame);
  CHECK(accumulator.report().world_session == 5);
  for (std::uint64_t tick = 1; tick <= 30; ++tick) accumulator.add(planes, contact.contact, force_N, 1e-3, tick);
  const Vector3d before_restart_Ns = sum_of_entries(accumulator.report());
  REQUIRE(before_restart_Ns.z() == Approx(-0.3));

  frame.frame_index = 1;  // the same world again: nothing changes
  accumulator.on_plane_frame(frame);
  CHECK(sum_of_entries(accumulator.report()) == before_restart_Ns);

  frame.world_session = 6;  // a restarted world
  frame.frame_index = 0;
  accumulator.on_plane_frame(frame);
  const HapticReport& report = accumulator.report();
  CHECK(report.world_session == 6);
  CHECK(report.entry_count == 0);
  CHECK(to_eigen(report.static_impulse_Ns) == Vector3d::Zero());
  CHECK(accumulator.abandoned_impulse_Ns() == before_restart_Ns);
  for (std::uint64_t tick = 31; tick <= 40; ++tick) accumulator.add(planes, contact.contact, force_N, 1e-3, tick);
  CHECK(sum_of_entries(report).z() == Approx(-0.1));  // only what was rendered against the new world
  // Nothing lost: every rendered impulse is in an entry, the static total or the abandoned total.
  const Vector3d accounted = sum_of_entries(report) + to_eigen(report.static_impulse_Ns) +
                             accumulator.abandoned_impulse_Ns() + accumulator.evicted_impulse_Ns() +
                             accumulator.dropped_impulse_Ns();
  CHECK((accounted - accumulator.total_impulse_Ns()).norm() < 1e-15);
}

TEST_CASE("the hand's input is each tick's push times the finger's velocity over the tick before, where it pushed") {
  // A finger pressing down into a cube's top by 1 mm per tick, then pulling back out at the same speed: the pushes on
  // the way in are the hand's input (J·v > 0), the way out gives nothing back to it (the world may not take the
  // hand's energy twice).
  ContactPlane cube_top = make_plane({0, 0, 0.05}, {0, 0, 1}, 1, true);
  cube_top.com_m = Vector3d(0, 0, 0.025);
  const PlaneSet planes = make_set({cube_top});
  ImpulseAccumulator accumulator(kSession);
  constexpr double kStiffness_Npm = 1000.0;
  constexpr double kTick_s = 1e-3;
  double expected_J = 0.0;
  double previous_z = 0.0;
  for (std::uint64_t tick = 1; tick <= 10; ++tick) {
    const double depth_m = 1e-3 * static_cast<double>(tick <= 5 ? tick : 10 - tick);
    const double z = 0.05 - depth_m;
    accumulator.report().finger_m = {0.0, 0.0, z};
    const Vector3d force_N(0.0, 0.0, kStiffness_Npm * depth_m);  // up on the finger
    GodObject god;
    const GodObjectResult& solved = god.solve(planes, Vector3d(0, 0, z), kTick_s);
    accumulator.add(planes, solved.contact, solved.contact.active_count > 0 ? force_N : Vector3d::Zero(), kTick_s,
                    tick);
    // −f·Δt on the cube, times the finger's velocity (z − previous)/Δt: positive while pressing in.
    if (tick > 1 && solved.contact.active_count > 0) {
      expected_J += std::max(0.0, -force_N.z() * kTick_s * (z - previous_z) / kTick_s);
    }
    previous_z = z;
  }
  REQUIRE(accumulator.report().entry_count == 1);
  // Pressing in over ticks 2..5: 1000 N/m · (2+3+4+5) mm · 1 mm = 14 mJ; pulling out adds nothing.
  CHECK(expected_J == Approx(0.014).epsilon(1e-12));
  CHECK(accumulator.report().entries[0].hand_input_J == Approx(expected_J).epsilon(1e-12));
}
