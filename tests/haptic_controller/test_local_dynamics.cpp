// SPDX-License-Identifier: Apache-2.0
// Local dynamics (haptic_controller/local_dynamics.h, paper §6.3): the haptic side moves the touched object
// between world frames. Physics-backed checks: a free body gives way by J/m per second, a sliding cube loses μ·g·h of
// speed per world substep and never reverses, a support blocks, a wrong model never pushes the finger out, and the
// impulse the model moved the object with is the impulse reported to the world.

#include "haptic_controller/local_dynamics.h"
#include "haptic_controller/servo.h"
#include "haptic_controller/device/spidar_kinematics.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

using namespace impetus;
using impetus::test::make_frame;
using impetus::test::wire_plane;
using Eigen::Vector3d;

namespace {

constexpr double kTick_s = 1e-3;

// A 1 kg cube (5 cm) whose −x face, at x = 0, faces a finger coming from −x.
Plane cube_face(double inverse_mass_per_kg = 1.0) {
  Plane plane = wire_plane(1, {0, 0, 0.05}, {-1, 0, 0});
  plane.inverse_mass_per_kg = inverse_mass_per_kg;
  const double inverse_inertia = 1.0 / (1.0 * 0.05 * 0.05 / 6.0);
  plane.inverse_inertia_world = {inverse_inertia, 0, 0, 0, inverse_inertia, 0, 0, 0, inverse_inertia};
  return plane;
}

PlaneFrame local_frame(std::initializer_list<Plane> planes, std::uint64_t index = 0) {
  PlaneFrame frame = make_frame(planes, index);
  frame.coupling = Coupling::local;
  frame.stiffness_Npm = 2000.0;
  frame.damping_Nspm = 0.0;
  return frame;
}

// A contact of the plane's object; `holds`: the other side takes the finger's push (static geometry or a grounded
// chain, kContactHolds), otherwise a loose neighbour.
// A local frame on Earth: gravity and the world's 5 ms substep, for models with supports.
PlaneFrame grounded_frame(const Plane& plane) {
  PlaneFrame frame = local_frame({plane});
  frame.gravity_mps2 = {0, 0, -9.81};
  frame.world_substep_s = 0.005;
  return frame;
}

void add_support(Plane& plane, const Vector3d& normal, double friction, bool holds = true) {
  impetus::LocalContact& contact = plane.local_contacts[plane.local_contact_count++];
  contact = impetus::LocalContact{};
  contact.normal = to_vec3(normal.normalized());
  contact.friction = friction;
  contact.flags = holds ? impetus::kContactHolds : 0u;
}


}  // namespace

TEST_CASE("local dynamics: a free body pushed by J gives way by J/m per second, and its plane with it") {
  LocalDynamics model;
  model.on_plane_frame(local_frame({cube_face()}), nullptr, Vector3d::Zero());
  PlaneSet planes;
  model.advance(kTick_s);
  model.render(kTick_s / 0.05, Vector3d(-0.01, 0, 0.05), planes);
  REQUIRE(planes.planes[0].point_m.x() == Approx(0.0).margin(1e-15));
  model.apply_impulse(1, Vector3d(0.01, 0, 0), Vector3d::Zero());  // 0.01 N·s on 1 kg: 1 cm/s
  for (int tick = 2; tick <= 21; ++tick) {
    model.advance(kTick_s);
    model.render(tick * kTick_s / 0.05, Vector3d(-0.01, 0, 0.05), planes);
  }
  // 20 ticks at 1 cm/s after the push: 0.2 mm, exactly (symplectic Euler of a free body).
  REQUIRE(planes.planes[0].point_m.x() == Approx(0.01 * 20 * kTick_s).epsilon(1e-12));
  REQUIRE(planes.planes[0].velocity_mps.x() == Approx(0.01));
  REQUIRE(model.find(1)->pushed_Ns.x() == Approx(0.01));
}

TEST_CASE("local dynamics: a cube sliding on the floor loses mu*g*h per world substep and stops without reversing") {
  Plane face = cube_face();
  face.velocity_mps = {0.1, 0, 0};
  add_support(face, Vector3d::UnitZ(), 0.5);
  LocalDynamics model;
  model.on_plane_frame(grounded_frame(face), nullptr, Vector3d::Zero());
  PlaneSet planes;
  double last_x = 0.0;
  for (int tick = 1; tick <= 10; ++tick) model.advance(kTick_s);
  // Two substeps started (t = 0 and 5 ms): v = 0.1 − 2·μ·g·h.
  REQUIRE(model.find(1)->velocity_mps.x() == Approx(0.1 - 2 * 0.5 * 9.81 * 0.005));
  REQUIRE(model.find(1)->velocity_mps.z() == Approx(0.0).margin(1e-15));  // the floor holds it up
  for (int tick = 11; tick <= 50; ++tick) {
    model.advance(kTick_s);
    model.render(tick / 50.0, Vector3d(-0.01, 0, 0.05), planes);
    REQUIRE(planes.planes[0].point_m.x() >= last_x);  // friction never drives it backwards
    last_x = planes.planes[0].point_m.x();
  }
  REQUIRE(model.find(1)->velocity_mps.x() == 0.0);
  REQUIRE(last_x > 0.0);
}

TEST_CASE("local dynamics: a push within a substep meets the rest of that substep's friction, as the world's solver "
          "has it") {
  // A 1 kg body on the floor (μ = 0.5, so μ·m·g = 4.9 N) pushed along +x every 1 ms tick. The model takes gravity,
  // the support and its friction once per 5 ms substep; the world solves a substep's forces together.
  const auto run = [](double force_N, int ticks) {
    Plane face = cube_face();
    add_support(face, Vector3d::UnitZ(), 0.5);
    LocalDynamics model;
    model.on_plane_frame(grounded_frame(face), nullptr, Vector3d::Zero());
    for (int tick = 0; tick < ticks; ++tick) {
      model.advance(kTick_s);
      model.apply_impulse(1, Vector3d(force_N * kTick_s, 0, 0), Vector3d::Zero());
    }
    return *model.find(1);
  };
  SECTION("below the friction limit the body stays where the floor holds it") {
    // 2 N: 10 mN·s a substep against a budget of 24.5 mN·s. A body that moved between the substeps' friction would
    // creep 0.03 mm a substep, 0.3 mm in 50 ms: what let a cube held on a ramp slide through a finger under delay.
    const LocalBody body = run(2.0, 50);
    CHECK(body.displacement_m.norm() < 1e-12);
    CHECK(body.velocity_mps.norm() < 1e-12);
  }
  SECTION("above it the body slides at (F − μ·m·g)/m, the budget spent and no more") {
    const LocalBody body = run(10.0, 50);
    // 50 ms of net 5.1 N on 1 kg: 0.255 m/s; pushes come every tick and the budget once a substep, so the speed is
    // within one substep's friction (24.5 mm/s) of it.
    CHECK(body.velocity_mps.x() == Approx((10.0 - 0.5 * 9.81) * 0.05).margin(0.5 * 9.81 * 0.005));
    CHECK(body.velocity_mps.x() < 10.0 * 0.05);
  }
}

TEST_CASE("local dynamics: a box on the floor brakes its spin at its four corners with the world's friction pyramid, "
          "and a box that only slides does not turn") {
  // The 1 kg, 5 cm cube resting on its face, floor friction 0.06, for `ticks` ticks (a 5 ms drift substep
  // starts every 5).
  auto box_on_floor = [](const Vector3d& velocity_mps, const Vector3d& angular_radps, int ticks) {
    Plane face = cube_face();
    impetus::test::set_shape(face, impetus::test::box_shape(Vector3d::Constant(0.025)));
    face.velocity_mps = to_vec3(velocity_mps);
    face.angular_velocity_radps = to_vec3(angular_radps);
    add_support(face, Vector3d::UnitZ(), 0.06);
    auto model = std::make_unique<LocalDynamics>();
    model->on_plane_frame(grounded_frame(face), nullptr, Vector3d::Zero());
    for (int tick = 1; tick <= ticks; ++tick) model->advance(kTick_s);
    return model;
  };
  const double mu_g_h = 0.06 * 9.81 * 0.005;  // the speed friction takes from a sliding body in one substep
  SECTION("spinning in place: each corner's friction at its pyramid limit on both axes") {
    // The first substep, square to the pyramid's axes (x and y, ODE's for a floor): the corners' torque about z is
    // 4 corners × 2 axes × (μ·m·g/4 per axis) × a lever of a = 2.5 cm, so dω = 2·a·μ·m·g·h / I, I = m·s²/6:
    // 0.353 rad/s. Without the corners the spin stayed at 6 rad/s.
    const double inertia_kgm2 = 0.05 * 0.05 / 6.0;
    const double first_rad_ps = 2 * 0.025 * mu_g_h / inertia_kgm2;
    CHECK(box_on_floor(Vector3d::Zero(), Vector3d(0, 0, -6), 1)->find(1)->angular_velocity_radps.z() ==
          Approx(-6.0 + first_rad_ps).epsilon(1e-12));
    // Then the box turns against the pyramid and its corners' levers along x and y shrink (to 1/√2 at 45°), as in
    // the world: ten substeps take between 1/√2 and all of ten times the first one's.
    const auto model = box_on_floor(Vector3d::Zero(), Vector3d(0, 0, -6), 50);
    const double braked_rad_ps = 6.0 + model->find(1)->angular_velocity_radps.z();
    CHECK(braked_rad_ps <= 10 * first_rad_ps);
    CHECK(braked_rad_ps > 10 * first_rad_ps / std::sqrt(2.0));
    CHECK(model->find(1)->velocity_mps.norm() < 1e-12);  // diagonal corners cancel: it spins in place
  }
  SECTION("pitching into the floor: the corners that would go in are held, the box pivots on that edge") {
    // ω about y drives the +x bottom corners down and lifts the −x ones: after the first substep no corner moves into
    // the floor, and the box turns about its +x bottom edge (the centre of mass rises) instead of through the floor.
    const auto model = box_on_floor(Vector3d::Zero(), Vector3d(0, 2, 0), 1);
    const LocalBody& box = *model->find(1);
    for (const double x : {-0.025, 0.025}) {
      for (const double y : {-0.025, 0.025}) {
        const Vector3d corner(x, y, -0.025);
        CHECK((box.velocity_mps + box.angular_velocity_radps.cross(corner)).z() >= -1e-12);
      }
    }
    CHECK(box.angular_velocity_radps.y() > 0.0);  // it may still tip that way: only the floor is enforced
    CHECK(box.velocity_mps.z() > 0.0);
  }
  SECTION("sliding: μ·g of braking, as at the centre of mass, and no turn") {
    const auto model = box_on_floor(Vector3d(0.3, 0, 0), Vector3d::Zero(), 50);
    CHECK(model->find(1)->velocity_mps.x() == Approx(0.3 - 10 * mu_g_h).epsilon(1e-9));
    CHECK(model->find(1)->velocity_mps.y() == Approx(0.0).margin(1e-9));
    CHECK(model->find(1)->angular_velocity_radps.norm() < 1e-9);
  }
}

TEST_CASE("local dynamics: a support blocks the push (a cube against a wall does not give way)") {
  Plane face = cube_face();
  add_support(face, -Vector3d::UnitX(), 0.2);  // a wall on the +x side pushes the cube toward −x
  LocalDynamics model;
  model.on_plane_frame(local_frame({face}), nullptr, Vector3d::Zero());
  PlaneSet planes;
  for (int tick = 1; tick <= 50; ++tick) {
    model.advance(kTick_s);
    model.render(tick / 50.0, Vector3d(-0.01, 0, 0.05), planes);
    model.apply_impulse(1, Vector3d(0.002, 0, 0), Vector3d::Zero());
  }
  REQUIRE(planes.planes[0].point_m.x() == 0.0);
}

// The floor a body has not reached (LocalContact::gap_m, world_manager/couplings/local_coupling.h): the model's body
// falls as a free body until it has covered the gap, then lands and stays, as the world's does. Over a delayed link
// the model may run a round trip on from its frame, so the landing must be its own.
TEST_CASE("local dynamics: a body above a floor it has not reached falls the gap and lands on it, not through it") {
  for (const double gap_m : {0.003, 0.02}) {
    CAPTURE(gap_m);
    Plane face = cube_face();
    face.velocity_mps = {0, 0, -0.05};  // set down at 5 cm/s
    add_support(face, Vector3d::UnitZ(), 0.5);
    face.local_contacts[0].gap_m = gap_m;
    Plane without = cube_face();
    without.velocity_mps = face.velocity_mps;
    LocalDynamics model, free_model;
    model.on_plane_frame(grounded_frame(face), nullptr, Vector3d::Zero());
    free_model.on_plane_frame(grounded_frame(without), nullptr, Vector3d::Zero());
    double lowest_m = 0.0, landed_s = -1.0, free_landed_s = -1.0;
    for (int tick = 1; tick <= 200; ++tick) {
      model.advance(kTick_s);
      free_model.advance(kTick_s);
      const double fallen_m = -model.find(1)->displacement_m.z();
      lowest_m = std::max(lowest_m, fallen_m);
      if (landed_s < 0.0 && fallen_m >= gap_m - 1e-12) landed_s = tick * kTick_s;
      if (free_landed_s < 0.0 && -free_model.find(1)->displacement_m.z() >= gap_m) free_landed_s = tick * kTick_s;
      // Before the substep it lands in it falls as the free body does, to rounding.
      if (free_landed_s < 0.0 && tick % 5 == 0) {
        REQUIRE(model.find(1)->displacement_m.z() == Approx(free_model.find(1)->displacement_m.z()).margin(1e-12));
      }
    }
    // It comes to the floor by the end of the substep in which the free body would pass it (5 ms), no farther (to
    // rounding), and stays on it: no bounce, no sinking.
    CHECK(landed_s >= free_landed_s);
    CHECK(landed_s <= free_landed_s + 0.005);
    CHECK(lowest_m == Approx(gap_m).margin(1e-12));
    CHECK(-model.find(1)->displacement_m.z() == Approx(gap_m).margin(1e-12));
    CHECK(model.find(1)->velocity_mps.z() == Approx(0.0).margin(1e-12));
    // The free body went on through where the floor is.
    CHECK(-free_model.find(1)->displacement_m.z() > gap_m + 0.01);
  }
}

TEST_CASE("local dynamics: a loose neighbour gives way to the push but carries the weight") {
  // The cube rests on a neighbour below and touches one on its +x side; neither is held (a pile of loose balls).
  Plane face = cube_face();
  add_support(face, Vector3d::UnitZ(), 0.05, false);
  add_support(face, -Vector3d::UnitX(), 0.05, false);
  LocalDynamics model;
  model.on_plane_frame(grounded_frame(face), nullptr, Vector3d::Zero());
  PlaneSet planes;
  for (int tick = 1; tick <= 50; ++tick) {
    model.advance(kTick_s);
    model.render(tick / 50.0, Vector3d(-0.01, 0, 0.05), planes);
    model.apply_impulse(1, Vector3d(0.002, 0, 0), Vector3d::Zero());
  }
  // Held up: the neighbour below takes g·h per substep, exactly what gravity adds.
  REQUIRE(std::abs(model.find(1)->velocity_mps.z()) < 1e-12);
  // Pushed into the side neighbour: it gives way, so the cube moves as a free one would (0.1 N·s on 1 kg), less the
  // friction of the weight-carrying contact below, μ·g·h = 2.5 mm/s per substep over at most 10 substeps.
  REQUIRE(planes.planes[0].point_m.x() > 0.0);
  REQUIRE(model.find(1)->velocity_mps.x() <= 0.1);
  REQUIRE(model.find(1)->velocity_mps.x() >= 0.1 - 10 * 0.05 * 9.81 * 0.005);
}

TEST_CASE("local dynamics: a loose neighbour with a mass shares the push, one that comes on keeps driving the body") {
  // A 1 kg cube touching a 3 kg neighbour on its +x side (contact normal −x on the cube), no gravity, no friction.
  SECTION("pushed into a resting neighbour: the two move off together, momentum shared") {
    Plane face = cube_face();
    add_support(face, -Vector3d::UnitX(), 0.0, false);
    face.local_contacts[0].other_inverse_mass_per_kg = 1.0 / 3.0;
    LocalDynamics model;
    model.on_plane_frame(local_frame({face}), nullptr, Vector3d::Zero());
    model.apply_impulse(1, Vector3d(0.4, 0, 0), Vector3d::Zero());
    CHECK(model.find(1)->velocity_mps.x() == Approx(0.1));  // 0.4 N·s over 4 kg
    CHECK(model.find(1)->neighbour_velocity_mps[0].x() == Approx(0.1));
  }
  SECTION("a heavy neighbour coming on at 0.5 m/s: a push back on the cube cannot send it through the neighbour") {
    Plane face = cube_face();
    face.velocity_mps = {-0.5, 0, 0};
    add_support(face, -Vector3d::UnitX(), 0.0, false);
    face.local_contacts[0].other_velocity_mps = {-0.5, 0, 0};
    face.local_contacts[0].other_inverse_mass_per_kg = 1.0 / 3.0;
    LocalDynamics model;
    model.on_plane_frame(local_frame({face}), nullptr, Vector3d::Zero());
    model.apply_impulse(1, Vector3d(1.0, 0, 0), Vector3d::Zero());  // enough to stop the cube alone twice over
    // Cube and neighbour: 4 kg at −0.5 m/s plus 1 N·s: both at −0.25 m/s, still coming on.
    CHECK(model.find(1)->velocity_mps.x() == Approx(-0.25));
    CHECK(model.find(1)->neighbour_velocity_mps[0].x() == Approx(-0.25));
  }
  SECTION("without a mass (static or unknown) a loose neighbour gives way as before") {
    Plane face = cube_face();
    add_support(face, -Vector3d::UnitX(), 0.0, false);
    LocalDynamics model;
    model.on_plane_frame(local_frame({face}), nullptr, Vector3d::Zero());
    model.apply_impulse(1, Vector3d(0.4, 0, 0), Vector3d::Zero());
    CHECK(model.find(1)->velocity_mps.x() == Approx(0.4));
  }
}

TEST_CASE("servo, local coupling: the pushed cube gives way between frames and the reported impulse is the one "
          "that moved it") {
  ServoOptions options;
  HapticServo servo(options, 3);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(local_frame({cube_face()}), 0.0);
  const FingerSample outside = test::finger_at(kinematics, Vector3d(-0.001, 0, 0.05));  // arrive from outside the face
  servo.tick(&outside, 0.0, kTick_s);
  const FingerSample state = test::finger_at(kinematics, Vector3d(0.002, 0, 0.05));  // then 2 mm into it, held
  for (int tick = 1; tick <= 40; ++tick) servo.tick(&state, tick * kTick_s, kTick_s);
  const LocalBody* body = servo.local_dynamics().find(1);
  REQUIRE(body != nullptr);
  REQUIRE(servo.planes().planes[0].point_m.x() > 0.0);  // gave way under the finger
  REQUIRE(servo.report().entry_count == 1);
  // Conservation: what moved the local model is what the world will apply (the report's running total).
  REQUIRE(body->pushed_Ns.x() == Approx(servo.report().entries[0].impulse_Ns[0]).epsilon(1e-12));
  // The time moments are Σ J_k·t_k, so the world can place the impulse where it was rendered.
  REQUIRE(servo.report().entries[0].impulse_moment_Nss[0] > 0.0);
  REQUIRE(servo.report().entries[0].impulse_moment_Nss[0] <= body->pushed_Ns.x() * 40 * kTick_s);
}

TEST_CASE("servo, local coupling: a 3 g body under the finger takes no more energy than the spring held") {
  // The finger starts 2 mm inside the face of a 3 g body and is held there. The contact spring holds ½·k·d² = 4 mJ;
  // that bounds what the body can carry away (the hand is still, so it does no work). With the tick solved
  // explicitly the loop gain (k·Δt² + b·Δt)/m = 2.4 makes the force flip sign every tick and grow.
  const double mass_kg = 0.0029;
  Plane face = cube_face(1.0 / mass_kg);
  const double inverse_inertia = 1.0 / (0.4 * mass_kg * 0.01 * 0.01);
  face.inverse_inertia_world = {inverse_inertia, 0, 0, 0, inverse_inertia, 0, 0, 0, inverse_inertia};
  PlaneFrame frame = local_frame({face});
  frame.damping_Nspm = 5.0;
  ServoOptions options;
  HapticServo servo(options, 3);
  const SpidarKinematics kinematics(SpidarGeometry{});
  servo.on_plane_frame(frame, 0.0);
  const FingerSample outside = test::finger_at(kinematics, Vector3d(-0.001, 0, 0.05));
  servo.tick(&outside, 0.0, kTick_s);
  const FingerSample inside = test::finger_at(kinematics, Vector3d(0.002, 0, 0.05));
  double largest_kinetic_J = 0.0;
  for (int tick = 1; tick <= 40; ++tick) {
    servo.tick(&inside, tick * kTick_s, kTick_s);
    const LocalBody* body = servo.local_dynamics().find(1);
    REQUIRE(body != nullptr);
    largest_kinetic_J = std::max(largest_kinetic_J, 0.5 * mass_kg * body->velocity_mps.squaredNorm());
  }
  REQUIRE(largest_kinetic_J > 0.0);                            // it was pushed
  REQUIRE(largest_kinetic_J <= 0.5 * 2000.0 * 0.002 * 0.002);  // by no more than the spring's energy
}

TEST_CASE("servo, local coupling: a wrong model (the world says the object did not move) never pushes the finger "
          "out") {
  // The finger holds still 2 mm inside the face; the model lets the cube give way, but every world frame puts it back
  // at x = 0 (stuck behind something the model was not told about). The plane may stay where the finger left it or
  // recede; it must never move toward the finger while pushing on it, so the work the plane does on the finger is
  // never positive. A 20 kg body, so the finger stays on it across frames (about 0.25 mm of give per frame).
  ServoOptions options;
  HapticServo servo(options, 3);
  const SpidarKinematics kinematics(SpidarGeometry{});
  const FingerSample outside = test::finger_at(kinematics, Vector3d(-0.001, 0, 0.05));
  const FingerSample state = test::finger_at(kinematics, Vector3d(0.002, 0, 0.05));
  servo.on_plane_frame(local_frame({cube_face(0.05)}), 0.0);
  servo.tick(&outside, 0.0, kTick_s);  // arrive from outside the face
  double work_on_finger_J = 0.0;
  double toward_finger_m = 0.0;  // largest step of the plane toward the finger while the finger is on it
  double last_plane_x = 0.0;
  int tick = 0;
  for (std::uint64_t frame = 0; frame < 10; ++frame) {
    servo.on_plane_frame(local_frame({cube_face(0.05)}, frame), tick * kTick_s);
    for (int j = 0; j < 50; ++j) {
      ++tick;
      const TickResult& r = servo.tick(&state, tick * kTick_s, kTick_s);
      const double plane_x = servo.planes().planes[0].point_m.x();
      // Plane displacement toward the finger is −x; the force on the finger is along −x: work = f_x·Δx.
      work_on_finger_J += r.force_N[0] * (plane_x - last_plane_x);
      if (r.active_planes > 0) toward_finger_m = std::max(toward_finger_m, last_plane_x - plane_x);
      last_plane_x = plane_x;
    }
  }
  REQUIRE(work_on_finger_J <= 1e-12);
  REQUIRE(toward_finger_m <= 1e-12);
  REQUIRE(servo.planes().planes[0].point_m.x() > 0.0);  // it did give way (softer, never active)
  REQUIRE(servo.counters().local_model_error_max_m > 0.0);  // the disagreement is visible in the diagnostic
}

TEST_CASE("servo: the frame-boundary diagnostic sees a plane jump under the finger and ignores steady motion") {
  ServoOptions options;
  options.stiffness_Npm = 1000.0;
  HapticServo servo(options, 3);
  const SpidarKinematics kinematics(SpidarGeometry{});
  const FingerSample above = test::finger_at(kinematics, Vector3d(0, 0, 0.001));
  const FingerSample state = test::finger_at(kinematics, Vector3d(0, 0, -0.002));
  // Impulse coupling, a static floor moving up steadily 1 mm per frame: interpolation is continuous, and at the
  // boundaries the second difference is zero.
  int tick = 0;
  servo.on_plane_frame(make_frame({wire_plane(0, {0, 0, -0.001}, {0, 0, 1}, false)}, 0), 0.0);
  servo.tick(&above, 0.0, 1e-3);  // arrive from above the floor
  for (std::uint64_t frame = 0; frame < 4; ++frame) {
    servo.on_plane_frame(make_frame({wire_plane(0, {0, 0, 0.001 * frame}, {0, 0, 1}, false)}, frame + 1),
                         tick * 1e-3);
    for (int j = 0; j < 50; ++j, ++tick) servo.tick(&state, (tick + 1) * 1e-3, 1e-3);
  }
  REQUIRE(servo.counters().contact_frame_boundaries >= 2);
  REQUIRE(servo.counters().frame_jump_max_m == Approx(0.0).margin(1e-9));
  // A frame that moves the plane by 0.5 mm at once while the finger is on it.
  // (Steady motion of 0.02 mm per tick before it: the second difference is 0.5 − 0.02 mm.)
  servo.on_plane_frame(make_frame({wire_plane(0, {0, 0, 0.0035}, {0, 0, 1}, false)}, 5), tick * 1e-3);
  servo.on_plane_frame(make_frame({wire_plane(0, {0, 0, 0.0035}, {0, 0, 1}, false)}, 6), tick * 1e-3);
  servo.tick(&state, (tick + 1) * 1e-3, 1e-3);
  REQUIRE(servo.counters().frame_jump_max_m == Approx(0.00048).margin(1e-6));
}

namespace {

// A 3 g wooden ball (r = 1 cm, hard case 10) centred at `centre`, its nearest point to a finger on the −x side, spinning
// at `spin` (rolling on the floor at 0.2 m/s is 20 rad/s). No contacts: nothing stops it turning.
Plane spinning_ball(const Vector3d& centre, const Vector3d& spin_radps) {
  const double radius_m = 0.01;
  const double mass_kg = 700.0 * 4.0 / 3.0 * 3.14159265358979 * radius_m * radius_m * radius_m;
  Plane plane = wire_plane(5, centre - Vector3d(radius_m, 0, 0), {-1, 0, 0});
  plane.com_m = to_vec3(centre);
  plane.angular_velocity_radps = to_vec3(spin_radps);
  plane.inverse_mass_per_kg = 1.0 / mass_kg;
  const double inverse_inertia = 1.0 / (0.4 * mass_kg * radius_m * radius_m);
  plane.inverse_inertia_world = {inverse_inertia, 0, 0, 0, inverse_inertia, 0, 0, 0, inverse_inertia};
  return plane;
}

}  // namespace

TEST_CASE("local dynamics: a spinning ball's plane does not sweep into a finger beside its tangent point (hard case "
          "10)") {
  // The finger is 0.2 mm outside the tangent plane but 2 cm along it (where it gets within a 10 Hz period): 12 mm from
  // the ball itself. A sphere's surface does not move when it spins, so nothing may push the finger. Rotating the
  // infinite plane with the ball about its centre swept it through the finger at ω·L = 20 rad/s · 2 cm = 0.4 m/s
  // within half a tick's angle (0.01 rad); that active wall, fed by the reaction at lever L, blew case 10 up.
  const Vector3d centre(0.0, 0.0, 0.01);
  const Vector3d finger(-0.0102, 0.02, 0.01);
  LocalDynamics model;
  model.on_plane_frame(local_frame({spinning_ball(centre, Vector3d(0, 0, 20))}), nullptr, finger);
  PlaneSet planes;
  double closest_m = 1.0;
  for (int tick = 1; tick <= 100; ++tick) {
    model.advance(kTick_s);
    model.render(tick / 100.0, finger, planes);
    const ContactPlane& plane = planes.planes[0];
    closest_m = std::min(closest_m, plane.normal.dot(finger - plane.point_m));
  }
  REQUIRE(closest_m == Approx(0.0002).margin(1e-9));
}

namespace {

// A ball of radius 1 cm resting on the floor (support +z, friction 0.5) and moving at `velocity`, spinning at `spin`.
Plane ball_on_floor(const Vector3d& velocity_mps, const Vector3d& spin_radps) {
  Plane plane = spinning_ball(Vector3d(0.0, 0.0, 0.01), spin_radps);
  impetus::test::set_shape(plane, impetus::test::round_shape(impetus::ShapeKind::sphere, 0.01));
  plane.velocity_mps = to_vec3(velocity_mps);
  add_support(plane, Vector3d::UnitZ(), 0.5);
  return plane;
}

}  // namespace

TEST_CASE("local dynamics: a ball rolling on the floor keeps its speed, a sliding one spins up to rolling at 5/7") {
  // The floor's friction acts at the contact point, as in the world: braking a rolling ball at μ·g would leave the
  // model's ball behind the world's when it comes to the finger.
  SECTION("rolling without slipping: v = ω × (r·z)") {
    LocalDynamics model;
    model.on_plane_frame(grounded_frame(ball_on_floor(Vector3d(1.0, 0, 0), Vector3d(0, 100.0, 0))), nullptr,
                         Vector3d(-0.1, 0, 0.01));
    for (int tick = 0; tick < 50; ++tick) model.advance(kTick_s);
    CHECK(model.find(5)->velocity_mps.x() == Approx(1.0).epsilon(1e-12));
    CHECK(model.find(5)->angular_velocity_radps.y() == Approx(100.0).epsilon(1e-12));
  }
  SECTION("sliding without spin: friction slows it and spins it up until it rolls, at 5/7 of its speed") {
    LocalDynamics model;
    model.on_plane_frame(grounded_frame(ball_on_floor(Vector3d(1.0, 0, 0), Vector3d::Zero())), nullptr,
                         Vector3d(-0.1, 0, 0.01));
    for (int tick = 0; tick < 100; ++tick) model.advance(kTick_s);  // rolling after 2v/(7μg) = 58 ms
    const double v = model.find(5)->velocity_mps.x();
    CHECK(v == Approx(5.0 / 7.0).epsilon(1e-9));
    CHECK(model.find(5)->angular_velocity_radps.y() * 0.01 == Approx(v).epsilon(1e-9));
  }
}

TEST_CASE("local dynamics: a spinning cylinder's and capsule's axes turn with the model, their plane does not") {
  // A cylinder and a capsule lying along x, spinning end over end about z at 1 rad/s; the plane is the side's top. In
  // 100 ticks the axis turns 0.1 rad, as the world's will; the plane itself is only carried with the centre (the
  // servo takes it again from the turned shape, shape_planes.h).
  for (const impetus::ShapeKind kind : {impetus::ShapeKind::cylinder, impetus::ShapeKind::capsule}) {
    Plane plane = wire_plane(3, {0.0, 0.0, 0.01}, {0, 0, 1});
    plane.com_m = {0.0, 0.0, 0.0};
    Eigen::Matrix3d along_x;
    along_x << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // body x, y, z along world y, z, x
    impetus::test::set_shape(plane, impetus::test::round_shape(kind, 0.01, 0.04), along_x);
    plane.inverse_mass_per_kg = 1.0;
    plane.inverse_inertia_world = {1e4, 0, 0, 0, 1e4, 0, 0, 0, 1e4};
    plane.angular_velocity_radps = {0.0, 0.0, 1.0};
    LocalDynamics model;
    model.on_plane_frame(local_frame({plane}), nullptr, Vector3d(0.0, 0.0, 0.02));
    PlaneSet planes;
    for (int tick = 1; tick <= 100; ++tick) {
      model.advance(kTick_s);
      model.render(tick / 50.0, Vector3d(0.0, 0.0, 0.02), planes);
    }
    const Vector3d axis = planes.planes[0].axes.col(2);
    CHECK((axis - Vector3d(std::cos(0.1), std::sin(0.1), 0.0)).norm() < 1e-9);
    CHECK((planes.planes[0].normal - Vector3d::UnitZ()).norm() < 1e-12);
  }
}

TEST_CASE("local dynamics: a free box spun off its principal axes precesses as a rigid body does (angular momentum "
          "kept, not the angular velocity)") {
  // A 1 kg box 3 × 2 × 1.2 cm, its axes along the world's at the frame, spinning at (2, 1.5, 1) rad/s: off every
  // principal axis, so ω moves while L = I·ω stays (Euler's equations without torque). Over a 10 Hz world's period
  // ω moves by about 0.2 rad/s, which a constant ω would miss by as much.
  const Vector3d half_m(0.015, 0.010, 0.006);
  const Vector3d inertia_kgm2(
      (4 * half_m.y() * half_m.y() + 4 * half_m.z() * half_m.z()) / 12.0,
      (4 * half_m.x() * half_m.x() + 4 * half_m.z() * half_m.z()) / 12.0,
      (4 * half_m.x() * half_m.x() + 4 * half_m.y() * half_m.y()) / 12.0);
  const Vector3d start_radps(2.0, 1.5, 1.0);
  Plane plane = wire_plane(4, {0.0, 0.0, half_m.z()}, {0, 0, 1});
  plane.com_m = {0.0, 0.0, 0.0};
  impetus::test::set_shape(plane, impetus::test::box_shape(half_m));
  plane.inverse_mass_per_kg = 1.0;
  plane.inverse_inertia_world = {1.0 / inertia_kgm2.x(), 0, 0, 0, 1.0 / inertia_kgm2.y(), 0, 0, 0, 1.0 / inertia_kgm2.z()};
  plane.angular_velocity_radps = to_vec3(start_radps);
  LocalDynamics model;
  model.on_plane_frame(local_frame({plane}), nullptr, Vector3d(0.0, 0.0, 0.05));
  for (int tick = 1; tick <= 100; ++tick) model.advance(kTick_s);

  // The reference: the same body integrated finely (RK4 at 10 µs) in the world frame, L fixed, ω = R·I⁻¹·Rᵀ·L.
  const Eigen::Matrix3d inverse_inertia_body = inertia_kgm2.cwiseInverse().asDiagonal();
  const Vector3d momentum = inertia_kgm2.cwiseProduct(start_radps);
  const auto omega = [&](const Eigen::Matrix3d& r) { return Vector3d(r * inverse_inertia_body * r.transpose() * momentum); };
  const auto rate = [&](const Eigen::Matrix3d& r) {
    const Vector3d w = omega(r);
    Eigen::Matrix3d cross;
    cross << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return Eigen::Matrix3d(cross * r);
  };
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  constexpr double kStep_s = 1e-5;
  for (int k = 0; k < 10000; ++k) {
    const Eigen::Matrix3d k1 = rate(r), k2 = rate(r + 0.5 * kStep_s * k1), k3 = rate(r + 0.5 * kStep_s * k2),
                          k4 = rate(r + kStep_s * k3);
    r += kStep_s / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  const Vector3d expected_radps = omega(r);
  const LocalBody* body = model.find(4);
  REQUIRE(body != nullptr);
  INFO("model " << body->angular_velocity_radps.transpose() << ", reference " << expected_radps.transpose());
  REQUIRE((expected_radps - start_radps).norm() > 0.1);  // the case does precess
  // First order in the tick: the model's ω lags the reference by about |ω̇|·Δt, 2 mrad/s here.
  CHECK((body->angular_velocity_radps - expected_radps).norm() < 0.01);
  // The turn it carries the faces with: within 1 mrad of the reference's (0.015 mm at the box's far corner).
  const Eigen::AngleAxisd off(body->turn.toRotationMatrix().transpose() * r);
  CHECK(std::abs(off.angle()) < 1e-3);
}

namespace {

// Ticks 1…last of a free 1 kg body pushed by `push` along +x every tick (the servo's order: note the tick, advance
// and render, then take the tick's share).
void push_ticks(LocalDynamics& model, std::uint64_t first, std::uint64_t last, const Vector3d& push_Ns) {
  PlaneSet planes;
  for (std::uint64_t tick = first; tick <= last; ++tick) {
    model.note_tick(tick);
    model.planes_for_tick(1.0, kTick_s, false, Vector3d(-0.01, 0, 0.05), planes);
    impetus::ImpulseShare share;
    share.object_id = 1;
    share.dynamic = true;
    share.impulse_Ns = push_Ns;
    model.take_shares(&share, 1);
  }
}

}  // namespace

TEST_CASE("local dynamics over a delayed link: a frame of the world before the last pushes is carried forward by "
          "them, so the model is where the finger has been pushing it") {
  constexpr std::uint64_t kSession = 7;
  const Vector3d push_Ns(0.001, 0.0, 0.0);  // 1 mN·s a tick on 1 kg: +1 mm/s per tick
  // Symplectic Euler of the model: after tick n the body moves at n·J/m and has moved J·Δt·n(n−1)/2 / m.
  const auto moved_m = [&](double n) { return push_Ns.x() * kTick_s * n * (n - 1.0) / 2.0; };

  // The finger pushed for 10 ticks; the world has applied the reports up to tick 4 only (a link delay), and its
  // frame, arriving now, says so: the cube where 4 pushes put it, at 4 mm/s.
  LocalDynamics model(kSession);
  PlaneFrame start = local_frame({cube_face()});
  model.on_plane_frame(start, nullptr, Vector3d::Zero());
  push_ticks(model, 1, 10, push_Ns);
  Plane late = cube_face();
  late.point_m = {moved_m(4), 0.0, 0.05};
  late.com_m = {0.025 + moved_m(4), 0.0, 0.05};
  late.velocity_mps = {4.0 * push_Ns.x(), 0.0, 0.0};
  PlaneFrame frame = local_frame({late}, 1);
  frame.report_tick_applied = 4;
  frame.report_session_applied = kSession;

  SECTION("the six pushes the world has not seen are replayed on its state") {
    model.on_plane_frame(frame, nullptr, Vector3d::Zero());
    CHECK(model.last_replayed_ticks() == 6);
    const LocalBody* body = model.find(1);
    REQUIRE(body != nullptr);
    CHECK(body->velocity_mps.x() == Approx(10.0 * push_Ns.x()).epsilon(1e-12));
    CHECK(body->com_m().x() == Approx(0.025 + moved_m(10)).epsilon(1e-12));
    // The frame's plane is moved with it: the face the finger feels is where the ten pushes put it.
    PlaneSet planes;
    model.note_tick(11);
    model.planes_for_tick(1.0, kTick_s, false, Vector3d(-0.01, 0, 0.05), planes);
    CHECK(planes.planes[0].point_m.x() == Approx(moved_m(11)).epsilon(1e-12));
  }
  SECTION("a frame naming another haptic session's report is taken as it is") {
    frame.report_session_applied = kSession + 1;
    model.on_plane_frame(frame, nullptr, Vector3d::Zero());
    CHECK(model.last_replayed_ticks() == 0);
    CHECK(model.find(1)->velocity_mps.x() == Approx(4.0 * push_Ns.x()));
  }
  SECTION("without delay (the frame applied the last tick rendered) nothing is replayed") {
    frame.report_tick_applied = 10;
    model.on_plane_frame(frame, nullptr, Vector3d::Zero());
    CHECK(model.last_replayed_ticks() == 0);
    CHECK(model.find(1)->velocity_mps.x() == Approx(4.0 * push_Ns.x()));
  }
  SECTION("a delay longer than the log holds restarts from the frame alone, and is counted") {
    push_ticks(model, 11, 10 + LocalDynamics::kLoggedTicks, push_Ns);
    model.on_plane_frame(frame, nullptr, Vector3d::Zero());
    CHECK(model.last_replayed_ticks() == 0);
    CHECK(model.replay_gaps() == 1);
    CHECK(model.find(1)->velocity_mps.x() == Approx(4.0 * push_Ns.x()));
  }
}

TEST_CASE("local dynamics over a delayed link: a body the replay carries over the finger does not push it out by "
          "the depth it was never pressed into, and that depth closes as the finger withdraws, not as the body "
          "leaves") {
  constexpr std::uint64_t kSession = 7;
  const Vector3d proxy_m(-0.05, 0.0, 0.05);
  // Ten ticks with no plane at all: the frame showing the cube has not arrived yet.
  LocalDynamics model(kSession);
  model.on_plane_frame(local_frame({}), nullptr, proxy_m);
  PlaneSet planes;
  for (std::uint64_t tick = 1; tick <= 10; ++tick) {
    model.note_tick(tick);
    model.planes_for_tick(1.0, kTick_s, false, proxy_m, planes);
  }
  // It arrives a round trip late (it applied tick 0): the cube's face 5 mm short of the proxy, coming on at 1 m/s.
  // The replay of ticks 1…10 carries it 10 mm on, 5 mm over the proxy.
  Plane face = cube_face();
  face.point_m = {-0.045, 0.0, 0.05};
  face.com_m = {-0.02, 0.0, 0.05};
  face.velocity_mps = {-1.0, 0.0, 0.0};
  PlaneFrame frame = local_frame({face}, 1);
  frame.report_tick_applied = 0;
  frame.report_session_applied = kSession;
  model.on_plane_frame(frame, &planes, proxy_m);
  REQUIRE(model.last_replayed_ticks() == 10);
  REQUIRE(model.find(1)->com_m().x() == Approx(-0.03).epsilon(1e-9));

  // The first tick: the plane starts at the proxy and moves on with the body by one tick's travel, 1 mm, not 6.
  model.note_tick(11);
  model.planes_for_tick(0.02, kTick_s, false, proxy_m, planes);
  REQUIRE(planes.count == 1);
  CHECK(planes.planes[0].point_m.x() == Approx(proxy_m.x() - 0.001).margin(1e-9));

  // The finger's push turns the body back (+1 m/s). With the finger still, the plane leaves with the body, 1 mm a
  // tick: the held depth does not close into the room the body makes.
  impetus::ImpulseShare share;
  share.object_id = 1;
  share.dynamic = true;
  share.impulse_Ns = {2.0, 0.0, 0.0};
  model.take_shares(&share, 1);
  const Vector3d pressed_m(proxy_m.x() - 0.001, 0.0, 0.05);  // the proxy on the plane it was pushed to
  model.note_tick(12);
  model.planes_for_tick(0.04, kTick_s, false, pressed_m, planes);
  CHECK(planes.planes[0].point_m.x() == Approx(pressed_m.x() + 0.001).margin(1e-9));
  model.note_tick(13);  // the proxy has followed the plane back toward the finger
  model.planes_for_tick(0.06, kTick_s, false, Vector3d(pressed_m.x() + 0.001, 0.0, 0.05), planes);
  CHECK(planes.planes[0].point_m.x() == Approx(pressed_m.x() + 0.002).margin(1e-9));

  // The finger withdraws 3 mm (−x): the plane closes toward the world's face by at most that clearance, to the proxy.
  const Vector3d withdrawn_m(pressed_m.x() + 0.002 - 0.003, 0.0, 0.05);
  model.note_tick(14);
  model.planes_for_tick(0.08, kTick_s, false, withdrawn_m, planes);
  const double closed_x = planes.planes[0].point_m.x();
  CHECK(closed_x < pressed_m.x() + 0.003 - 1e-4);  // it closed (the body alone would have put it at +3 mm)
  CHECK(closed_x >= withdrawn_m.x() - 1e-9);       // never past the proxy
}
