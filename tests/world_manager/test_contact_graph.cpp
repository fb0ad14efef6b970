// SPDX-License-Identifier: Apache-2.0
// Which contacts hold the finger's push in the local model (contact_graph.h): a chain of contacts within their
// friction cones to static geometry holds; a loose neighbour does not.

#include "world_manager/features/contact_graph.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>

using impetus::ContactGraph;
using impetus::kContactHolds;
using impetus::LocalContact;
using Eigen::Vector3d;

namespace {

constexpr std::int32_t kStatic = ContactGraph::kStatic;

// A contact between two bodies, seen from both sides (as the world records it): `normal` pushes `a` out of `b`.
void touch(ContactGraph& graph, std::int32_t a, std::int32_t b, const Vector3d& normal, double friction) {
  graph.add(a, b, normal, friction);
  graph.add(b, a, -normal, friction);
}

}  // namespace

TEST_CASE("contact graph: a stack on the floor holds a press from above, four corner contacts are one support") {
  ContactGraph graph;
  graph.reset(2);
  for (int corner = 0; corner < 4; ++corner) graph.add(0, kStatic, Vector3d::UnitZ(), 0.3);  // box 0 on the floor
  for (int corner = 0; corner < 4; ++corner) touch(graph, 1, 0, Vector3d::UnitZ(), 0.3);     // box 1 on box 0
  graph.finish();

  std::array<LocalContact, impetus::kMaxLocalContacts> contacts{};
  REQUIRE(graph.local_contacts(1, {}, contacts) == 1);
  REQUIRE(impetus::to_eigen(contacts[0].normal).isApprox(Vector3d::UnitZ()));
  REQUIRE((contacts[0].flags & kContactHolds) != 0);
  // Box 0 has the floor below (holds) and box 1 above: pushing box 1 up is not held by anything.
  REQUIRE(graph.local_contacts(0, {}, contacts) == 2);
  for (int c = 0; c < 2; ++c) {
    const bool below = impetus::to_eigen(contacts[c].normal).z() > 0.0;
    REQUIRE(((contacts[c].flags & kContactHolds) != 0) == below);
  }
}

TEST_CASE("contact graph: a loose row of balls gives way sideways, the same row against a wall holds") {
  ContactGraph graph;
  graph.reset(3);
  for (std::int32_t ball = 0; ball < 3; ++ball) graph.add(ball, kStatic, Vector3d::UnitZ(), 0.4);
  touch(graph, 0, 1, -Vector3d::UnitX(), 0.4);  // ball 1 is on ball 0's +x side
  touch(graph, 1, 2, -Vector3d::UnitX(), 0.4);
  graph.finish();
  REQUIRE(!graph.holds(1, Vector3d::UnitX()));
  REQUIRE(!graph.holds(1, -Vector3d::UnitX()));

  graph.reset(3);
  for (std::int32_t ball = 0; ball < 3; ++ball) graph.add(ball, kStatic, Vector3d::UnitZ(), 0.4);
  touch(graph, 0, 1, -Vector3d::UnitX(), 0.4);
  touch(graph, 1, 2, -Vector3d::UnitX(), 0.4);
  graph.add(2, kStatic, -Vector3d::UnitX(), 0.4);  // a wall beyond ball 2
  graph.finish();
  REQUIRE(graph.holds(1, Vector3d::UnitX()));    // toward the wall, through ball 2
  REQUIRE(!graph.holds(1, -Vector3d::UnitX()));  // away from it

  std::array<LocalContact, impetus::kMaxLocalContacts> contacts{};
  REQUIRE(graph.local_contacts(0, {}, contacts) == 2);
  for (std::uint32_t c = 0; c < 2; ++c) REQUIRE((contacts[c].flags & kContactHolds) != 0);
}

TEST_CASE("contact graph: a contact holds a push within its friction cone only") {
  const double mu = 0.3;  // cone half-angle atan 0.3 = 16.7°
  for (const double degrees : {0.0, 10.0, 16.0, 17.5, 30.0, 80.0}) {
    ContactGraph graph;
    graph.reset(1);
    graph.add(0, kStatic, Vector3d::UnitZ(), mu);
    graph.finish();
    const double angle = degrees * M_PI / 180.0;
    const Vector3d push(std::sin(angle), 0.0, -std::cos(angle));  // into the floor, tilted by `degrees`
    REQUIRE(graph.holds(0, push) == (angle <= std::atan(mu)));
  }
}

TEST_CASE("contact graph: bad input is ignored, and a cycle of contacts ends") {
  ContactGraph graph;
  graph.reset(2);
  graph.add(5, kStatic, Vector3d::UnitZ(), 0.3);                        // no such body
  graph.add(0, 7, Vector3d::UnitZ(), 0.3);                              // no such neighbour
  graph.add(0, kStatic, Vector3d(NAN, 0, 0), 0.3);                      // not finite
  graph.add(0, kStatic, Vector3d::Zero(), 0.3);                         // no direction
  graph.add(0, 1, Vector3d::UnitZ(), 0.3);                              // 0 → 1 → 0: a cycle that never
  graph.add(1, 0, Vector3d::UnitZ(), 0.3);                              // reaches static geometry
  graph.finish();
  REQUIRE(!graph.holds(0, -Vector3d::UnitZ()));
  std::array<LocalContact, impetus::kMaxLocalContacts> contacts{};
  REQUIRE(graph.local_contacts(0, {}, contacts) == 1);
  REQUIRE((contacts[0].flags & kContactHolds) == 0);
  REQUIRE(graph.local_contacts(9, {}, contacts) == 0);
}

TEST_CASE("contact graph: a contact with a dynamic body carries its velocity and inverse mass, the floor none, the "
          "friction capacity is the sum of mu times each contact's normal force") {
  ContactGraph graph;
  graph.reset(2);
  graph.add(0, kStatic, Vector3d::UnitZ(), 0.5, 9.81);        // body 0 on the floor, weight 9.81 N
  graph.add(0, 1, -Vector3d::UnitX(), 0.2, 2.0);              // body 1 presses on its +x side with 2 N
  graph.add(1, 0, Vector3d::UnitX(), 0.2, 2.0);
  graph.finish();
  std::vector<impetus::ObjectState> states(2);
  states[1].velocity_mps = Vector3d(-0.3, 0.0, 0.0);
  states[1].inverse_mass_per_kg = 0.5;
  std::array<LocalContact, impetus::kMaxLocalContacts> contacts{};
  REQUIRE(graph.local_contacts(0, states, contacts) == 2);
  for (int c = 0; c < 2; ++c) {
    const bool floor = impetus::to_eigen(contacts[c].normal).z() > 0.5;
    CHECK(contacts[c].other_inverse_mass_per_kg == (floor ? 0.0 : 0.5));
    CHECK(contacts[c].other_velocity_mps[0] == (floor ? 0.0 : -0.3));
  }
  CHECK(graph.friction_capacity_N(0) == Approx(0.5 * 9.81 + 0.2 * 2.0));
  CHECK(graph.friction_capacity_N(1) == Approx(0.2 * 2.0));
}

TEST_CASE("contact graph: a sleeping body keeps the contacts it fell asleep with until it wakes") {
  ContactGraph graph;
  graph.reset(3);
  for (int corner = 0; corner < 4; ++corner) graph.add(0, kStatic, Vector3d::UnitZ(), 0.4, 1.0);  // box 0 on the floor
  touch(graph, 1, 0, Vector3d::UnitZ(), 0.4);  // box 1 on box 0
  graph.finish();
  graph.rest(0);  // box 0 sleeps: the engine no longer collides it
  graph.rest(1);

  // The next substep's graph has only the awake body 2, on the floor.
  graph.reset(3);
  graph.add(2, kStatic, Vector3d::UnitZ(), 0.4, 2.0);
  graph.finish();
  CHECK(graph.touching(0));
  CHECK(graph.friction_capacity_N(0) == Approx(4 * 0.4 * 1.0));
  CHECK(graph.holds(1, -Vector3d::UnitZ()));  // box 1, pressed down, is still held through sleeping box 0
  std::array<LocalContact, impetus::kMaxLocalContacts> contacts{};
  CHECK(graph.local_contacts(0, {}, contacts) == 2);  // the floor and box 1
  CHECK(graph.friction_capacity_N(2) == Approx(0.4 * 2.0));

  // Box 0 wakes: its sleeping contacts last until the next graph, which has its new ones (none here).
  graph.wake(0);
  CHECK(graph.touching(0));
  graph.reset(3);
  graph.finish();
  CHECK_FALSE(graph.touching(0));
  CHECK(graph.touching(1));  // still asleep
  // Asleep again: what the graph had for it then (nothing) is what it keeps.
  graph.rest(0);
  CHECK_FALSE(graph.touching(0));
}

TEST_CASE("contact graph: the weight the contacts do not carry is the slope's share of it, none on a floor") {
  const Vector3d weight_N(0.0, 0.0, -10.0);
  ContactGraph graph;
  graph.reset(3);
  for (int corner = 0; corner < 4; ++corner) graph.add(0, kStatic, Vector3d::UnitZ(), 0.3, 2.5);  // on a floor
  // On a slope of 30° rising along +x: its normal leans back along −x.
  const Vector3d slope(-std::sin(M_PI / 6), 0.0, std::cos(M_PI / 6));
  graph.add(1, kStatic, slope, 0.3, 8.66);
  graph.finish();  // body 2 touches nothing
  CHECK(graph.unsupported_weight_N(0, weight_N).norm() < 1e-12);
  const Vector3d loose = graph.unsupported_weight_N(1, weight_N);
  CHECK(loose.dot(slope) == Approx(0.0).margin(1e-12));  // along the slope, down it (−x), m·g·sin 30°
  CHECK(loose.norm() == Approx(5.0));
  CHECK(loose.x() < 0.0);
  CHECK(graph.unsupported_weight_N(2, weight_N) == weight_N);
  // A contact above it carries none of it (a box pressed from above).
  graph.reset(1);
  graph.add(0, kStatic, -Vector3d::UnitZ(), 0.3, 4.0);
  graph.finish();
  CHECK(graph.unsupported_weight_N(0, weight_N) == weight_N);
}
