// SPDX-License-Identifier: Apache-2.0
// Sleeping is engine-neutral (engine/sleeping_bodies.h): any engine that can take a body out of its solver and put it
// back gets it. Here a fake engine of boxes on a line, touching when their boxes overlap.
#include "world_manager/engine/sleeping_bodies.h"
#include "world_manager/features/contact_graph.h"
#include "world_manager/scene.h"

#include <catch2/catch.hpp>

#include <set>
#include <vector>

namespace {

using impetus::SleepingBodies;

class BoxesOnALine final : public SleepingBodies::Engine {
 public:
  std::vector<double> x_m;                 // per object: its 1 cm box spans [x, x + 0.01]
  std::vector<double> reach_m;             // per object: how far it may move in the coming substep
  std::set<std::size_t> in_solver, rested_now;
  std::vector<std::size_t> entered, left;  // the calls, in order

  Eigen::AlignedBox3d bounds(std::size_t id) const override {
    return Eigen::AlignedBox3d(Eigen::Vector3d(x_m[id], 0, 0), Eigen::Vector3d(x_m[id] + 0.01, 0.01, 0.01));
  }
  Eigen::AlignedBox3d reach_bounds(std::size_t id, double) override {
    Eigen::AlignedBox3d box = bounds(id);
    box.max().x() += reach_m[id];
    return box;
  }
  bool reaches(std::size_t id, std::size_t other) override {
    return x_m[id] + 0.01 + reach_m[id] >= x_m[other] && x_m[other] + 0.01 >= x_m[id];
  }
  bool rested(std::size_t id) const override { return rested_now.count(id) > 0; }
  void leave_solver(std::size_t id) override {
    REQUIRE(in_solver.erase(id) == 1);
    left.push_back(id);
  }
  void enter_solver(std::size_t id) override {
    REQUIRE(in_solver.insert(id).second);
    entered.push_back(id);
  }
};

}  // namespace

TEST_CASE("sleeping bodies: rested bodies leave the solver, and an awake one wakes what it reaches, in a chain") {
  // 0: a fixed wall at 1 m. 1, 2: bodies 1 cm apart at 0.00 and 0.02; 3 touches 2 at 0.03; 4 is far away at 0.5 m.
  BoxesOnALine engine;
  engine.x_m = {1.0, 0.0, 0.02, 0.03, 0.5};
  engine.reach_m.assign(5, 0.0);
  impetus::ContactGraph graph;
  graph.reset(5);
  const impetus::EscapeGuard guard(5);
  SleepingBodies sleeping(5, 0.05, guard, graph);
  sleeping.add_fixed(0, engine.bounds(0));
  for (std::size_t id = 1; id < 5; ++id) {
    sleeping.add_awake(id);
    engine.in_solver.insert(id);
  }
  CHECK(sleeping.moved() == std::vector<std::size_t>{1, 2, 3, 4});  // every body before the first step

  // 2, 3 and 4 come to rest; 1 does not.
  sleeping.begin_step();
  engine.rested_now = {2, 3, 4};
  sleeping.put_rested_to_sleep(engine);
  CHECK(engine.left == std::vector<std::size_t>{2, 3, 4});
  CHECK(sleeping.awake() == std::vector<std::size_t>{1});
  CHECK(sleeping.asleep(3));
  CHECK_FALSE(sleeping.asleep(0));
  std::vector<std::size_t> fixed;
  sleeping.fixed_near(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(2, 1, 1)), fixed);
  CHECK(fixed == std::vector<std::size_t>{0});  // sleepers are in the grid, but not fixed

  // Next step: 1 stays 1 cm short of 2 in this substep: nothing wakes, and the step moves 1 only.
  engine.rested_now.clear();
  sleeping.begin_step();
  sleeping.wake_touched(0.005, engine);
  CHECK(engine.entered.empty());
  CHECK(sleeping.moved() == std::vector<std::size_t>{1});
  // 1 would reach 2 within the substep: 2 wakes, and 3, which 2 touches, wakes in turn; 4 sleeps on.
  engine.reach_m[1] = 0.015;
  sleeping.wake_touched(0.005, engine);
  CHECK(engine.entered == std::vector<std::size_t>{2, 3});
  CHECK(sleeping.awake() == std::vector<std::size_t>{1, 2, 3});
  CHECK(sleeping.moved() == std::vector<std::size_t>{1, 2, 3});
  CHECK(sleeping.asleep(4));
  // A push wakes a sleeper directly; waking an awake body does nothing.
  sleeping.wake(4, engine);
  sleeping.wake(4, engine);
  CHECK(engine.entered == std::vector<std::size_t>{2, 3, 4});
  CHECK(sleeping.moved() == std::vector<std::size_t>{1, 2, 3, 4});
}

TEST_CASE("sleeping bodies: a parked body leaves the awake list and is never put to sleep or woken") {
  BoxesOnALine engine;
  engine.x_m = {0.0, 0.011};
  engine.reach_m = {0.0, 0.0};
  impetus::ContactGraph graph;
  graph.reset(2);
  impetus::EscapeGuard guard(2);
  SleepingBodies sleeping(2, 0.05, guard, graph);
  sleeping.add_awake(0);
  sleeping.add_awake(1);
  engine.in_solver = {0, 1};
  class ParkFirst final : public impetus::EscapeGuard::Engine {
   public:
    std::optional<impetus::EscapeGuard::BodyState> escape_state(std::size_t id) const override {
      const double x_m = id == 0 ? 2.0 * impetus::kEscapeDistance_m : 0.0;
      return impetus::EscapeGuard::BodyState{Eigen::Vector3d(x_m, 0, 0), Eigen::Vector3d::Zero(),
                                             Eigen::Vector3d::Zero(), Eigen::Vector4d(1, 0, 0, 0)};
    }
    void park(std::size_t, const Eigen::Vector3d&, bool) override {}
  } park_first;
  guard.check_all(park_first);
  REQUIRE(guard.escaped(0));
  engine.rested_now = {0, 1};
  sleeping.put_rested_to_sleep(engine);
  CHECK(engine.left == std::vector<std::size_t>{1});
  CHECK(sleeping.awake().empty());
  CHECK_FALSE(sleeping.asleep(0));
}
