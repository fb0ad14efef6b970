// SPDX-License-Identifier: Apache-2.0
// Speculative contacts (engine/speculative_contacts.h, scene physics.speculative_contacts): a pair that meets within a
// substep closes its gap and no more, so an impact neither sinks into the other body nor bounces off the penetration
// correction. Each world test runs with them off too, where the fault they remove must show.
#include "world_manager/engine/speculative_contacts.h"
#include "world_manager/scene.h"

#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <optional>
#include <span>

namespace impetus {
namespace {

// The 5 ms substep of the default 20 Hz × 10 world, as one substep per world step so every substep is observed.
nlohmann::json substep_physics(bool speculative) {
  return {{"world_rate_hz", 200}, {"substeps", 1}, {"auto_disable", false}, {"speculative_contacts", speculative}};
}

void step(World& world) { world.step(std::span<const HapticReport* const>{}); }

struct Drop {
  double deepest_m = 0.0;         // the ball's deepest point below the floor's surface, over the run
  double impact_speed_mps = 0.0;  // its fastest fall
  double rebound_speed_mps = 0.0; // its fastest rise after the first impact
};

// A 2 cm wooden ball dropped from 13 cm above the floor (1.6 m/s at the floor: 8 mm per 5 ms substep), for 0.4 s.
Drop drop_ball(double restitution, bool speculative) {
  const nlohmann::json document{
      {"physics", substep_physics(speculative)},
      {"floor", {{"restitution", restitution}}},
      {"objects",
       {{{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.02}, {"dynamic", true}, {"mass_kg", 0.023},
         {"position_m", {0.0, 0.0, 0.15}}, {"restitution", restitution}}}}};
  auto world = test::make_world(parse_scene(document, "drop.json"));
  Drop drop;
  bool fell = false;
  for (int i = 0; i < 80; ++i) {
    step(*world);
    const ObjectState& ball = world->states()[0];
    drop.deepest_m = std::max(drop.deepest_m, 0.02 - ball.pose.position_m.z());
    const double vz = ball.velocity_mps.z();
    if (!fell) drop.impact_speed_mps = std::max(drop.impact_speed_mps, -vz);
    if (vz > 0.0) fell = true;
    if (fell) drop.rebound_speed_mps = std::max(drop.rebound_speed_mps, vz);
  }
  return drop;
}

}  // namespace

TEST_CASE("speculative contacts: a dropped ball meets the floor without sinking in and bounces as its restitution "
          "says") {
  const double restitution = GENERATE(0.0, 0.5);
  const Drop with = drop_ball(restitution, true);
  const Drop without = drop_ball(restitution, false);
  INFO("restitution " << restitution << ": deepest " << with.deepest_m * 1e3 << " mm (off: " << without.deepest_m * 1e3
                      << " mm); impact " << with.impact_speed_mps << " m/s, rebound " << with.rebound_speed_mps
                      << " m/s (off: " << without.rebound_speed_mps << " m/s)");
  REQUIRE(with.impact_speed_mps > 1.5);
  // Without them the ball ends its impact substep up to v·h = 8 mm deep; with them only the contact's softness
  // (m·g/k: microns) is left.
  CHECK(without.deepest_m > 1e-3);
  CHECK(with.deepest_m < 0.02e-3);
  if (restitution == 0.0) {
    // No bounce: the floor does not hand back what the correction of a penetration would (ERP·depth/h).
    CHECK(with.rebound_speed_mps < 0.01);
    CHECK(without.rebound_speed_mps > 0.05);
  } else {
    // The rebound is e times the impact speed, less the one substep of gravity it spends at the surface (g·h).
    CHECK(with.rebound_speed_mps == Approx(restitution * with.impact_speed_mps).margin(9.81 * 0.005 + 1e-3));
  }
}

TEST_CASE("speculative contacts: a cube sliding into another passes on its momentum without a kick") {
  // Free space: a 1 kg cube at 0.5 m/s and a 0.5 kg one 11.25 mm ahead (the impact falls mid-substep, where the
  // penetration, and so the correction's kick, is largest). Restitution 0: they go on together at m1·v/(m1 + m2).
  auto run = [](bool speculative) {
    nlohmann::json document = test::free_body_document(
        {{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true}, {"mass_kg", 1.0},
         {"position_m", {0.0, 0.0, 0.0}}, {"linear_velocity_mps", {0.5, 0.0, 0.0}}});
    document["objects"].push_back({{"name", "cube2"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}},
                                   {"dynamic", true}, {"mass_kg", 0.5}, {"position_m", {0.06125, 0.0, 0.0}}});
    document["physics"] = substep_physics(speculative);
    auto world = test::make_world(parse_scene(document, "two_cubes.json"));
    double deepest_m = 0.0;
    for (int i = 0; i < 100; ++i) {
      step(*world);
      deepest_m = std::max(deepest_m, 0.05 - (world->states()[1].pose.position_m.x() -
                                              world->states()[0].pose.position_m.x()));
    }
    const double parting_mps = world->states()[1].velocity_mps.x() - world->states()[0].velocity_mps.x();
    const double momentum_Ns = world->states()[0].velocity_mps.x() + 0.5 * world->states()[1].velocity_mps.x();
    return std::tuple{deepest_m, parting_mps, momentum_Ns, world->states()[1].velocity_mps.x()};
  };
  const auto [deepest_m, parting_mps, momentum_Ns, second_mps] = run(true);
  const auto [off_deepest_m, off_parting_mps, off_momentum_Ns, off_second_mps] = run(false);
  INFO("with: deepest " << deepest_m * 1e3 << " mm, parting at " << parting_mps << " m/s; off: deepest "
                        << off_deepest_m * 1e3 << " mm, parting at " << off_parting_mps << " m/s");
  CHECK(momentum_Ns == Approx(0.5).epsilon(1e-9));
  CHECK(off_momentum_Ns == Approx(0.5).epsilon(1e-9));
  CHECK(deepest_m < 0.02e-3);
  CHECK(std::abs(parting_mps) < 1e-3);
  CHECK(second_mps == Approx(0.5 / 1.5).epsilon(0.01));
  // Off: the cubes end the impact substep 1.25 mm into each other and the correction parts them.
  CHECK(off_deepest_m > 1e-3);
  CHECK(off_parting_mps > 0.01);
}

TEST_CASE("speculative contacts: a fast ball wakes the sleeping box it is about to hit and meets it as a body") {
  // The box sleeps after 0.5 s at rest; the ball rolls at 2 m/s (1 cm per substep) and arrives at about 0.75 s. It
  // must wake the box one substep early, so that the two meet without overlapping: a sleeping box is fixed geometry
  // until woken, with no speculative contacts of its own.
  nlohmann::json physics = substep_physics(true);
  physics["auto_disable"] = true;
  const nlohmann::json document{
      {"physics", physics},
      {"objects",
       {{{"name", "box"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true}, {"mass_kg", 0.5},
         {"position_m", {0.0, 0.0, 0.025}}},
        {{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.02}, {"dynamic", true}, {"mass_kg", 0.2},
         {"position_m", {-1.5453, 0.0, 0.02}}, {"linear_velocity_mps", {2.0, 0.0, 0.0}},
         {"angular_velocity_radps", {0.0, 100.0, 0.0}}}}}};
  auto world = test::make_world(parse_scene(document, "wake.json"));
  for (int i = 0; i < 130; ++i) step(*world);  // 0.65 s
  REQUIRE(world->asleep(0));
  REQUIRE(world->states()[1].pose.position_m.x() < -0.1);
  double deepest_m = 0.0;
  for (int i = 0; i < 200; ++i) {
    step(*world);
    deepest_m = std::max(deepest_m, (world->states()[1].pose.position_m.x() + 0.02) -
                                        (world->states()[0].pose.position_m.x() - 0.025));
  }
  INFO("box at x = " << world->states()[0].pose.position_m.x() << " m, ball at "
                     << world->states()[1].pose.position_m.x() << " m; deepest overlap " << deepest_m * 1e3 << " mm");
  CHECK(world->states()[0].pose.position_m.x() > 0.01);  // struck at ~0.6 m/s, braked at mu·g: ~3 cm
  // Woken on contact instead, the ball ends its arrival substep up to v·h = 10 mm inside. What is left is the
  // contact's give under the impact (~60 N for one substep) and the box's tilt, which this centre-line measure
  // counts as overlap: below 0.1 mm.
  CHECK(deepest_m < 0.1e-3);
}

namespace {

// An engine of one ball above a floor (id 1 with one object), colliding analytically: enough to check what the
// service decides without any physics engine.
class BallOverFloor final : public SpeculativeContacts::Engine {
 public:
  Eigen::Vector3d centre_m{0.1, 0.2, 0.021234};  // 1.234 mm above the floor
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  double radius_m = 0.02;
  std::vector<SpeculativeContacts::Row> rows;
  int ordinary_pairs = 0;

  std::optional<SpeculativeContacts::Motion> motion(std::size_t id) const override {
    if (id != 0) return std::nullopt;
    return SpeculativeContacts::Motion{centre_m, velocity_mps, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                       0.1, true, false};
  }
  Eigen::AlignedBox3d bounds(std::size_t id) const override {
    if (id != 0) return Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 0));
    return Eigen::AlignedBox3d(centre_m.array() - radius_m, centre_m.array() + radius_m);
  }
  int collide_displaced(std::size_t id, std::size_t other, const Eigen::Vector3d& displacement_m,
                        SpeculativeContacts::Point* out) override {
    REQUIRE(id == 0);
    REQUIRE(other == 1);
    const Eigen::Vector3d at = centre_m + displacement_m;
    const double depth_m = radius_m - at.z();
    if (depth_m < 0.0) return 0;
    out[0] = {at - radius_m * Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), depth_m};  // the ball's lowest point
    return 1;
  }
  void add_row(std::size_t, std::size_t, const SpeculativeContacts::Row& row) override { rows.push_back(row); }
  void add_ordinary_contacts(std::size_t, std::size_t) override { ++ordinary_pairs; }
};

}  // namespace

TEST_CASE("speculative contacts service: the gap a ball closes on the floor, over any engine that collides") {
  const std::vector<Material> materials(2);  // the ball's and the floor's; no restitution
  const EscapeGuard guard(1);
  const Eigen::Vector3d no_gravity = Eigen::Vector3d::Zero();
  SpeculativeContacts service(1, true, no_gravity, materials, guard, nullptr);
  BallOverFloor engine;
  const std::vector<std::size_t> movers{0};
  constexpr double kSubstep_s = 0.005;

  // Falling 3 mm in the substep: reaches. One row, 1.234 mm apart, midway across the gap below the centre, asking
  // the pair to close at most the gap in the substep.
  engine.velocity_mps = {0.0, 0.0, -0.003 / kSubstep_s};
  service.begin_substep(kSubstep_s);
  service.predict(movers, engine);
  service.speculate(movers, engine);
  REQUIRE(engine.rows.size() == 1);
  const SpeculativeContacts::Row& row = engine.rows[0];
  CHECK(row.speculative);
  CHECK(row.point.depth_m == 0.0);
  CHECK(row.normal_speed_mps == Approx(-0.001234 / kSubstep_s).epsilon(1e-9));
  CHECK(row.point.normal == Eigen::Vector3d::UnitZ());
  CHECK(row.point.position_m.x() == Approx(0.1));
  CHECK(row.point.position_m.z() == Approx(0.000617).margin(1e-12));

  // Falling 1 mm: falls short, nothing. Moving along the floor: nothing.
  for (const Eigen::Vector3d& velocity_mps : {Eigen::Vector3d(0.0, 0.0, -0.001 / kSubstep_s),
                                             Eigen::Vector3d(0.01 / kSubstep_s, 0.0, 0.0)}) {
    engine.rows.clear();
    engine.velocity_mps = velocity_mps;
    service.begin_substep(kSubstep_s);
    service.predict(movers, engine);
    service.speculate(movers, engine);
    CHECK(engine.rows.empty());
  }

  // Already touching and closing fast: the engine is told to leave the pair to the service, which gives it the
  // contact of where it will be (an ordinary row: it overlaps) instead of the engine's own.
  engine.rows.clear();
  engine.centre_m.z() = 0.019;
  engine.velocity_mps = {0.0, 0.0, -0.2};
  service.begin_substep(kSubstep_s);
  service.predict(movers, engine);
  const SpeculativeContacts::Point touch{Eigen::Vector3d(0.1, 0.2, -0.0005), Eigen::Vector3d::UnitZ(), 0.001};
  CHECK(service.defer_touching(0, 1, touch, engine));
  service.add_closing_contacts(engine);
  service.speculate(movers, engine);  // a touching pair is not speculated on again
  REQUIRE(engine.rows.size() == 1);
  CHECK_FALSE(engine.rows[0].speculative);
  CHECK(engine.rows[0].point.depth_m == Approx(0.001).margin(1e-12));  // the overlap now, carried back
  CHECK(engine.ordinary_pairs == 0);
  // Resting on it: the engine keeps its own contacts.
  engine.velocity_mps.setZero();
  service.begin_substep(kSubstep_s);
  CHECK_FALSE(service.defer_touching(0, 1, touch, engine));

  // A parked ball is never tested.
  EscapeGuard parked(1);
  class ParkAll final : public EscapeGuard::Engine {
   public:
    std::optional<EscapeGuard::BodyState> escape_state(std::size_t) const override {
      return EscapeGuard::BodyState{Eigen::Vector3d(2.0 * kEscapeDistance_m, 0, 0), Eigen::Vector3d::Zero(),
                                    Eigen::Vector3d::Zero(), Eigen::Vector4d(1, 0, 0, 0)};
    }
    void park(std::size_t, const Eigen::Vector3d&, bool) override {}
  } park_all;
  parked.check_all(park_all);
  SpeculativeContacts after_escape(1, true, no_gravity, materials, parked, nullptr);
  engine.rows.clear();
  engine.centre_m.z() = 0.021234;
  engine.velocity_mps = {0.0, 0.0, -0.003 / kSubstep_s};
  after_escape.begin_substep(kSubstep_s);
  after_escape.predict(movers, engine);
  after_escape.speculate(movers, engine);
  CHECK(engine.rows.empty());
}

}  // namespace impetus
