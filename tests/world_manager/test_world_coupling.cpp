// SPDX-License-Identifier: Apache-2.0
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <limits>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>

using impetus::Coupling;
using impetus::HapticReport;
using impetus::World;
using impetus::WorldOptions;
using impetus::test::add_entry;
using impetus::test::make_report;
using impetus::test::make_world;
using Eigen::Vector3d;
using nlohmann::json;

namespace {

// Velocities are compared after one application: only rounding of one product and sum separates them.
constexpr double kRelativeTolerance = 1e-12;

// An asymmetric box (2 kg, 0.1 × 0.2 × 0.3 m), rotated, free in space: the world inertia is a full matrix, so a wrong
// frame for I⁻¹ shows up.
json tilted_box() {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.6, Vector3d(1, -2, 0.5).normalized()));
  return json{{"name", "box"}, {"shape", "box"}, {"size_m", {0.1, 0.2, 0.3}}, {"dynamic", true}, {"mass_kg", 2.0},
              {"position_m", {0, 0, 0}}, {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

Eigen::Matrix3d analytic_inverse_inertia_world(const Eigen::Quaterniond& q, double mass_kg, const Vector3d& size_m) {
  // Solid box: I_xx = m (b² + c²) / 12 about the centre, and so on.
  const Vector3d s2 = size_m.cwiseProduct(size_m);
  const Vector3d inertia_kgm2 = mass_kg / 12.0 * Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  const Eigen::Matrix3d r = q.toRotationMatrix();
  return r * inertia_kgm2.cwiseInverse().asDiagonal() * r.transpose();
}

bool close(const Vector3d& a, const Vector3d& b) { return (a - b).norm() <= kRelativeTolerance * (1.0 + b.norm()); }

}  // namespace

TEST_CASE("an impulse gives exactly dv = J/m, and the world inverse inertia is R I^-1 R^T") {
  const impetus::Scene scene = impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json");
  auto world = make_world(scene);
  const Eigen::Quaterniond q = world->states()[0].pose.orientation;
  const Eigen::Matrix3d expected_inverse = analytic_inverse_inertia_world(q, 2.0, {0.1, 0.2, 0.3});
  CHECK((world->states()[0].inverse_inertia_world - expected_inverse).norm() <= 1e-9 * expected_inverse.norm());

  HapticReport report = make_report(42, 50);
  add_entry(report, 0, 1, {0.3, -0.2, 0.1});
  world->step(&report);
  // Free flight with no gravity: the velocity after the step is exactly the impulse's.
  CHECK(close(world->states()[0].velocity_mps, Vector3d(0.15, -0.1, 0.05)));
  CHECK(close(world->step_impulse_Ns(0), Vector3d(0.3, -0.2, 0.1)));
}

TEST_CASE("an angular impulse gives exactly dw = I^-1 L on a free body") {
  // A cube's inertia is isotropic, so free rotation keeps ω constant through the step and ω after the step is I⁻¹L.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.9, Vector3d(0.3, 1, -0.4).normalized()));
  const json cube{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                  {"mass_kg", 1.0}, {"position_m", {0, 0, 0}}, {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(cube), "free.json"));
  HapticReport report = make_report(7, 50);
  const Vector3d angular_impulse_Nms(2e-4, -1e-4, 3e-4);
  add_entry(report, 0, 1, {0, 0, 0}, impetus::to_vec3(angular_impulse_Nms));
  world->step(&report);
  const double inertia_kgm2 = 1.0 * (0.05 * 0.05 + 0.05 * 0.05) / 12.0;
  CHECK(close(world->states()[0].angular_velocity_radps, angular_impulse_Nms / inertia_kgm2));

  // On the asymmetric box, the change applied at the step start is I_world⁻¹·L (checked through the state the world
  // used; free precession changes ω afterwards, so compare against the angular momentum instead: it is conserved).
  auto box_world = make_world(impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json"));
  const Eigen::Matrix3d inverse_before = box_world->states()[0].inverse_inertia_world;
  HapticReport box_report = make_report(7, 50);
  add_entry(box_report, 0, 1, {0, 0, 0}, impetus::to_vec3(angular_impulse_Nms));
  box_world->step(&box_report);
  const impetus::ObjectState& after = box_world->states()[0];
  const Vector3d momentum_Nms = after.inverse_inertia_world.inverse() * after.angular_velocity_radps;
  INFO("L after " << momentum_Nms.transpose() << ", ω0 = " << (inverse_before * angular_impulse_Nms).transpose());
  // ODE's implicit gyroscopic term conserves |L| only to first order in ω·dt (here ω·dt ~ 1e-3).
  CHECK((momentum_Nms - angular_impulse_Nms).norm() < 1e-3 * angular_impulse_Nms.norm());
}

TEST_CASE("a repeated report applies nothing twice") {
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json"));
  HapticReport report = make_report(42, 50);
  add_entry(report, 0, 3, {0.4, 0.0, 0.0});
  world->step(&report);
  world->step(&report);
  world->step(&report);
  CHECK(close(world->states()[0].velocity_mps, Vector3d(0.2, 0.0, 0.0)));
  CHECK(close(world->total_impulse_Ns(0), Vector3d(0.4, 0.0, 0.0)));
  CHECK(world->step_impulse_Ns(0).norm() == 0.0);

  // The total grows: only the growth is applied.
  report.tick = 100;
  report.entries[0].impulse_Ns = {0.6, 0.0, 0.0};
  world->step(&report);
  CHECK(close(world->step_impulse_Ns(0), Vector3d(0.2, 0.0, 0.0)));
  CHECK(close(world->states()[0].velocity_mps, Vector3d(0.3, 0.0, 0.0)));
}

// Reports of whole N·s in one step: more than a device renders, so the world's bound on a report's impulse
// (World::take_report) is lifted to test the ledger alone.
impetus::WorldOptions unbounded_reports() {
  impetus::WorldOptions options;
  options.report_force_limit_N = std::numeric_limits<double>::infinity();
  return options;
}

TEST_CASE("a restarted haptic session or a new epoch starts from a zero baseline: no burst") {
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json"),
                          unbounded_reports());
  HapticReport first = make_report(42, 50);
  add_entry(first, 0, 1, {10.0, 0.0, 0.0});  // a long session has accumulated a large total
  world->step(&first);
  CHECK(close(world->states()[0].velocity_mps, Vector3d(5.0, 0.0, 0.0)));

  SECTION("new session") {
    HapticReport restarted = make_report(43, 1);  // a new controller counts from zero again
    add_entry(restarted, 0, 1, {0.2, 0.0, 0.0});
    world->step(&restarted);
    // Applied: the new total itself (0.2), not 0.2 − 10 (a backwards burst) nor 10 again.
    CHECK(close(world->step_impulse_Ns(0), Vector3d(0.2, 0.0, 0.0)));
    CHECK(close(world->states()[0].velocity_mps, Vector3d(5.1, 0.0, 0.0)));
  }
  SECTION("new epoch in the same session") {
    HapticReport reallocated = make_report(42, 60);
    add_entry(reallocated, 0, 2, {0.2, 0.0, 0.0});
    world->step(&reallocated);
    CHECK(close(world->step_impulse_Ns(0), Vector3d(0.2, 0.0, 0.0)));
  }
}

TEST_CASE("a report bringing more impulse than a device renders in the time it covers is cut to that, counted") {
  // 10 N over one 50 ms step is 0.5 N·s. A report claiming 1.61 N·s in one step (a world resumed after a stall, whose
  // controller rendered against a frozen plane all along; or a rogue participant) gets 0.5 and 1.11 is counted.
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json"));
  const double period_s = world->world_period_s();
  REQUIRE(period_s == Approx(0.05));
  HapticReport report = make_report(7, 50);
  add_entry(report, 0, 1, {1.61, 0.0, 0.0});
  world->step(&report);
  CHECK(world->step_impulse_Ns(0).x() == Approx(10.0 * period_s).epsilon(1e-8));
  CHECK(world->clipped_reports() == 1);
  CHECK(world->clipped_impulse_Ns() == Approx(1.61 - 10.0 * period_s).epsilon(1e-8));
  // The report of haptic tick `tick` (1 kHz) with the running total `total_Ns` along x, stepped once.
  const auto step_with_total = [&](std::uint64_t tick, double total_Ns) {
    report.tick = tick;
    report.haptic_time_s = static_cast<double>(tick) * 1e-3;
    report.entries[0].impulse_Ns = {total_Ns, 0.0, 0.0};
    world->step(&report);
  };
  // Within the bound: applied whole. The next report covers one step; 0.4 N·s more is within 0.5.
  step_with_total(100, 2.01);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.4));
  CHECK(world->clipped_reports() == 1);
  // Three steps without a new report, then one covering them: four steps' worth of force may have gone in.
  for (int k = 0; k < 3; ++k) world->step(std::span<const HapticReport* const>{});
  step_with_total(300, 2.01 + 1.9);
  CHECK(world->step_impulse_Ns(0).x() == Approx(1.9));
  CHECK(world->clipped_reports() == 1);
  // The same report again for three steps (a transport keeps the last one while the link is down and the controller
  // renders on), then a new one: it covers all four steps.
  for (int k = 0; k < 3; ++k) world->step(&report);
  step_with_total(500, 3.91 + 1.9);
  CHECK(world->step_impulse_Ns(0).x() == Approx(1.9));
  CHECK(world->clipped_reports() == 1);
  // Shares on several contacts: |Σ ΔJ| ≤ F·T and Σ|ΔJ| ≤ √3·F·T. Two opposite shares of 0.6 N·s each (a pinch) sum
  // to zero but are more than √3·0.5 together.
  HapticReport pinch = make_report(8, 50);
  add_entry(pinch, 0, 1, {0.6, 0.0, 0.0});
  pinch.static_impulse_Ns = {-0.6, 0.0, 0.0};
  world->step(&pinch);
  CHECK(world->clipped_reports() == 2);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.5 * 1.7320508075688772 * 0.5).epsilon(1e-8));
}

TEST_CASE("a report covering more rendering than its step (a lossy link, a late step) goes in whole, a stall's not") {
  // Steps 50 ms apart, the device's limit 10 N: 0.5 N·s a step.
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(tilted_box()), "free.json"));
  HapticReport report = make_report(7, 100);
  add_entry(report, 0, 1, {0.1, 0.0, 0.0});
  const auto step_with_total = [&](std::uint64_t tick, double total_Ns) {
    report.tick = tick;
    report.haptic_time_s = static_cast<double>(tick) * 1e-3;
    report.entries[0].impulse_Ns = {total_Ns, 0.0, 0.0};
    world->step(&report);
  };
  step_with_total(100, 0.1);
  // The report of tick 150 lost, the world reads tick 140's, then tick 200's: 60 ms of rendering in a 50 ms step,
  // which the device could have pushed at 10 N all along.
  step_with_total(140, 0.5);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.4));
  step_with_total(200, 1.1);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.6));
  // A step woken 3 ms late reads a report 3 ms fresher than its last (a loaded machine; the next step is on time
  // again and reads 3 ms less): nothing was lost to a stall, so the 53 ms of pushing go in whole.
  step_with_total(253, 1.63);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.53));
  step_with_total(300, 2.1);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.47));
  CHECK(world->clipped_reports() == 0);
  // A stall: the world's clock skipped two steps (100 ms it did not simulate), and the report then covers 150 ms of
  // pushing against a plane that stood still. One step simulated, one step's 0.5 N·s goes in.
  world->note_skipped_steps(2);
  step_with_total(450, 3.6);
  CHECK(world->step_impulse_Ns(0).x() == Approx(0.5).epsilon(1e-8));
  CHECK(world->clipped_reports() == 1);
  // A haptic time far ahead of the world's (a rogue clock) stands for at most the world time covered and one step.
  step_with_total(10450, 100.0);
  CHECK(world->step_impulse_Ns(0).x() == Approx(1.0).epsilon(1e-8));
  CHECK(world->clipped_reports() == 2);
}

TEST_CASE("entries on static geometry or unknown ids move nothing") {
  json document = impetus::test::free_body_document(tilted_box());
  document["objects"].push_back(json{{"name", "wall"}, {"shape", "box"}, {"size_m", {0.1, 0.1, 0.1}},
                                     {"dynamic", false}, {"position_m", {1, 0, 0}}});
  auto world = make_world(impetus::parse_scene(document, "free.json"), unbounded_reports());
  HapticReport report = make_report(5, 50);
  add_entry(report, 1, 1, {1.0, 0.0, 0.0});   // the static wall
  add_entry(report, 99, 1, {1.0, 0.0, 0.0});  // no such object
  report.static_impulse_Ns = {0.0, 0.0, -0.5};
  world->step(&report);
  CHECK(world->states()[0].velocity_mps.norm() == 0.0);
  CHECK(world->rejected_entries() == 1);
  CHECK(close(world->total_static_impulse_Ns(), Vector3d(1.0, 0.0, -0.5)));
  world->step(&report);  // cumulative: nothing new
  CHECK(close(world->total_static_impulse_Ns(), Vector3d(1.0, 0.0, -0.5)));
}

TEST_CASE("a frame names the report of a haptic side that has seen no world yet and rendered nothing, so the "
          "round trip is measured from the first frame, but not one that rendered impulse against no world of ours") {
  const json cube{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                  {"mass_kg", 1.0}, {"position_m", {0.03, 0.0, 0.025}}};
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(cube), "free.json"));
  HapticReport fresh = make_report(4, 50, {0.0, 0.0, 0.025}, true);
  fresh.world_session = 0;  // no frame seen yet
  const impetus::PlaneFrame& first = world->step(&fresh);
  CHECK(world->foreign_reports() == 1);  // still not counted against this world
  CHECK(first.report_session_applied == 4);
  CHECK(first.report_tick_applied == 50);
  HapticReport rendered = make_report(5, 60, {0.0, 0.0, 0.025}, true);
  rendered.world_session = 0;
  add_entry(rendered, 0, 1, {0.5, 0.0, 0.0});  // impulse rendered against no world of ours: not named, not applied
  const impetus::PlaneFrame& second = world->step(&rendered);
  CHECK(second.report_session_applied == 4);  // the frame keeps the last report it could name
  CHECK(world->states()[0].velocity_mps.norm() == 0.0);
}

TEST_CASE("a report counted against another world session moves nothing, but its finger still brings planes") {
  // A 1 kg cube in free space. The report's totals were rendered against a world that is gone (a restart), or
  // before any frame: this world must not apply them, neither now nor later.
  const json cube{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                  {"mass_kg", 1.0}, {"position_m", {0.03, 0.0, 0.025}}};
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(cube), "free.json"));
  HapticReport report = make_report(4, 50, {0.0, 0.0, 0.025}, true);
  report.world_session = WorldOptions{}.world_session + 1;
  add_entry(report, 0, 1, {0.5, 0.0, 0.0});
  const impetus::PlaneFrame& frame = world->step(&report);
  CHECK(world->total_impulse_Ns(0).norm() == 0.0);
  CHECK(world->states()[0].velocity_mps.norm() == 0.0);
  CHECK(world->foreign_reports() == 1);
  CHECK(frame.plane_count > 0);            // the finger is still where the planes come from
  CHECK(frame.report_session_applied == 0);  // and nothing counts as applied
  // The haptic side adopts this world (its totals restart from zero, a new epoch); from then on it is applied.
  report.world_session = WorldOptions{}.world_session;
  report.entries[0].epoch = 2;
  report.entries[0].impulse_Ns = {0.25, 0.0, 0.0};
  world->step(&report);
  CHECK(close(world->total_impulse_Ns(0), Vector3d(0.25, 0.0, 0.0)));
}

TEST_CASE("position coupling pushes with k_p times the penetration, held for the world period") {
  // A 1 kg cube at rest in free space; the finger is 4 mm inside its −x face and still.
  const json cube{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                  {"mass_kg", 1.0}, {"position_m", {0.03, 0.0, 0.025}}};
  WorldOptions options;
  options.coupling = Coupling::position;
  options.position_stiffness_Npm = 2000.0;
  options.position_damping_Nspm = 5.0;
  auto world = make_world(impetus::parse_scene(impetus::test::free_body_document(cube), "free.json"), options);
  constexpr double kDepth_m = 0.004;
  HapticReport report = make_report(1, 50, {0.005 + kDepth_m, 0.0, 0.025}, true);
  add_entry(report, 0, 1, {5.0, 0.0, 0.0});  // ignored in position coupling
  world->step(&report);
  // Still finger, still cube: no damping term; the force acts through the face centre, so no torque.
  const Vector3d expected_force_N(2000.0 * kDepth_m, 0.0, 0.0);
  const double period_s = world->world_period_s();
  CHECK(close(world->step_impulse_Ns(0), expected_force_N * period_s));  // the force held for the period
  CHECK(close(world->states()[0].velocity_mps, expected_force_N * period_s / 1.0));
  CHECK(world->states()[0].angular_velocity_radps.norm() < 1e-12);
}

TEST_CASE("no report, or a report without a finger, leaves the world to itself and publishes no planes") {
  auto world = make_world(impetus::load_scene(impetus::test::scene_path("tap.json")));
  const impetus::PlaneFrame& frame = world->step(nullptr);
  CHECK(frame.frame_index == 0);
  CHECK(frame.plane_count == 0);
  HapticReport report = make_report(3, 50, {0.0, 0.0, 0.025}, false);
  CHECK(world->step(&report).plane_count == 0);
  report.finger_valid = 1;
  const impetus::PlaneFrame& touched = world->step(&report);
  CHECK(touched.plane_count == 2);  // the cube's −x face and the floor
  CHECK(touched.frame_index == 2);
  CHECK(touched.report_tick_applied == 50);
  CHECK(touched.report_session_applied == 3);
  CHECK(impetus::test::transport_verdict(touched) == impetus::FrameError::ok);
}

namespace {

// A 1 kg, 5 cm cube resting on the default floor (friction 0.5: μ·m·g = 4.9 N), let settle for `settle_steps`.
std::unique_ptr<World> resting_cube(const impetus::Scene& scene, Coupling coupling, int settle_steps) {
  WorldOptions options;
  options.coupling = coupling;
  auto world = make_world(scene, options);
  for (int i = 0; i < settle_steps; ++i) world->step(nullptr);
  return world;
}

json floor_cube() {
  return json{{"objects", {{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                            {"mass_kg", 1.0}, {"position_m", {0, 0, 0.025}}}}}};
}

// Steps the world `steps` times with a steady push `force_N` on the cube, reported as the haptic side does: each
// report adds one period's impulse to the running total, its moment rendered evenly over the period.
// `after_step(step)` is called after each step.
void push_steadily(World& world, const Vector3d& force_N, int steps,
                   const std::function<void(int)>& after_step = [](int) {}) {
  const double period_s = world.world_period_s();
  HapticReport report = make_report(7, 0);
  report.entry_count = 1;
  impetus::ObjectImpulse& entry = report.entries[0];
  entry.object_id = 0;
  entry.epoch = 1;
  constexpr int kTicks = 50;
  for (int step = 0; step < steps; ++step) {
    for (int tick = 1; tick <= kTicks; ++tick) {
      const double t_s = step * period_s + tick * period_s / kTicks;
      for (int a = 0; a < 3; ++a) {
        entry.impulse_Ns[a] += force_N[a] * period_s / kTicks;
        entry.impulse_moment_Nss[a] += force_N[a] * period_s / kTicks * t_s;
      }
    }
    report.tick = static_cast<std::uint64_t>((step + 1) * kTicks);
    report.haptic_time_s = (step + 1) * period_s;
    entry.last_tick = report.tick;
    world.step(&report);
    after_step(step);
  }
}

}  // namespace

TEST_CASE("a steady push that friction holds leaves a resting cube where it was, under impulse and local coupling") {
  // 2 N is 41 % of μ·m·g: static friction holds it. Concentrated into one of the step's 10 substeps the same push
  // would be 20 N against that substep's friction and the cube would creep about 0.1 mm per step.
  const impetus::Scene scene = impetus::parse_scene(floor_cube(), "cube.json");
  for (Coupling coupling : {Coupling::impulse, Coupling::local}) {
    INFO("coupling " << impetus::to_string(coupling));
    auto world = resting_cube(scene, coupling, 20);
    const Vector3d start = world->states()[0].pose.position_m;
    push_steadily(*world, Vector3d(2.0, 0.0, 0.0), 200);  // 10 s
    const Vector3d moved = world->states()[0].pose.position_m - start;
    CHECK(std::hypot(moved.x(), moved.y()) < 1e-4);
    // And every bit of it was applied.
    CHECK(world->total_impulse_Ns(0).x() == Approx(2.0 * 200 * world->world_period_s()).epsilon(1e-12));
  }
}

TEST_CASE("impulse coupling: a steady push that holds a cube on a slope is a force, and the cube stays") {
  // The floor tilted by tilting gravity 25°: the cube's weight along the slope, m·g·sin 25° = 4.15 N, is more than
  // its friction holds (μ·m·g·cos 25° = 0.89 N at μ = 0.1), so it slides unless pushed. A steady 4.15 N push up the
  // slope holds it still with no work done; as a kick of all but the friction's share at each step's start it would
  // throw the cube up the slope and let it slide back every step.
  const double tilt = 25.0 * M_PI / 180.0;
  json tilted = floor_cube();
  tilted["gravity_mps2"] = {-9.81 * std::sin(tilt), 0.0, -9.81 * std::cos(tilt)};
  tilted["floor"] = {{"static_friction", 0.1}};
  const impetus::Scene scene = impetus::parse_scene(tilted, "slope.json");
  WorldOptions options;
  options.coupling = Coupling::impulse;
  auto world = make_world(scene, options);
  const Vector3d hold_N(9.81 * std::sin(tilt), 0.0, 0.0);
  // Its first step has no contacts to hold the push yet: the cube is let settle under it for 10 steps, then 10 s.
  Vector3d settled = Vector3d::Zero();
  push_steadily(*world, hold_N, 210, [&](int step) {
    if (step == 9) settled = world->states()[0].pose.position_m;
  });
  CHECK(std::abs(world->states()[0].pose.position_m.x() - settled.x()) < 1e-4);
  CHECK(world->total_impulse_Ns(0).x() == Approx(hold_N.x() * 210 * world->world_period_s()).epsilon(1e-12));
}

TEST_CASE("impulse coupling: a push beyond what friction holds moves the cube at once, with the exact momentum") {
  // A 0.5 N·s tap on a cube whose floor contact holds at most μ·N·T ≈ 0.12 N·s in a 20 Hz step: the excess is a
  // velocity change at the start of the step (paper §3.5); friction then takes μ·g·T ≈ 0.25 m/s off it in the step.
  const impetus::Scene scene = impetus::parse_scene(floor_cube(), "cube.json");
  auto world = resting_cube(scene, Coupling::impulse, 20);
  HapticReport report = make_report(7, 50);
  add_entry(report, 0, 1, {0.5, 0.0, 0.0});
  world->step(&report);
  CHECK(world->step_impulse_Ns(0).x() == 0.5);
  const double speed = world->states()[0].velocity_mps.x();
  const double friction_dv = 0.5 * 9.81 * world->world_period_s();
  CHECK(speed == Approx(0.5 - friction_dv).margin(0.02));
}

TEST_CASE("a finger that comes back after its device stalled meets the face it went in by, not the far face") {
  // The tap scene's cube (1 kg, 5 cm, centre x = 0.03 m): the proxy at its −x face, then the device stalls (reports
  // without a finger) for 5 world steps while the finger goes on moving, and comes back with its proxy 1 cm past the
  // cube's centre. The world must give the −x face meanwhile and after (the one the proxy went in by): the far face would put the
  // proxy outside through the +x side and pull the finger on through.
  impetus::prepare_engines();
  const impetus::Scene scene = impetus::load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json");
  impetus::World world(scene, impetus::WorldOptions{});
  HapticReport report = make_report(7, 1, {0.006, 0.0, 0.025}, true);
  report.proxy_m = {0.005, 0.0, 0.025};
  auto cube_plane_normal_x = [&](const impetus::PlaneFrame& frame) {
    for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
      if (frame.planes[k].object_id == 0) return frame.planes[k].normal[0];
    }
    return 0.0;
  };
  CHECK(cube_plane_normal_x(world.step(&report)) < -0.99);  // the −x face
  report.finger_valid = 0;
  for (int step = 0; step < 5; ++step) {
    ++report.tick;
    CHECK(cube_plane_normal_x(world.step(&report)) < -0.99);  // meanwhile the planes around where the proxy was
  }
  ++report.tick;
  report.finger_valid = 1;
  report.finger_m = {0.045, 0.0, 0.025};
  report.proxy_m = {0.04, 0.0, 0.025};  // past the centre: the +x face is now the nearer one
  CHECK(cube_plane_normal_x(world.step(&report)) < -0.99);
}
