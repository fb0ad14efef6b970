// SPDX-License-Identifier: Apache-2.0
// The escape guard is engine-neutral: any engine that can read a body and park it gets it (here a fake one).
#include "world_manager/engine/escape_guard.h"
#include "world_manager/scene.h"

#include <catch2/catch.hpp>

#include <limits>
#include <map>

namespace {

using impetus::EscapeGuard;

class FakeEngine final : public EscapeGuard::Engine {
 public:
  std::map<std::size_t, EscapeGuard::BodyState> bodies;  // the simulated ones
  std::map<std::size_t, std::pair<Eigen::Vector3d, bool>> parked;

  std::optional<EscapeGuard::BodyState> escape_state(std::size_t id) const override {
    const auto found = bodies.find(id);
    if (found == bodies.end()) return std::nullopt;
    return found->second;
  }
  void park(std::size_t id, const Eigen::Vector3d& position_m, bool reset_orientation) override {
    parked[id] = {position_m, reset_orientation};
  }
};

EscapeGuard::BodyState at(const Eigen::Vector3d& position_m) {
  return {position_m, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector4d(1, 0, 0, 0)};
}

}  // namespace

TEST_CASE("escape guard: bodies out of range or with a state that is not finite are parked once, in order") {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const double far_m = 2.0 * impetus::kEscapeDistance_m;
  FakeEngine engine;
  engine.bodies[0] = at({0.1, 0.0, 0.0});            // in range: stays
  engine.bodies[1] = at({0.0, far_m, 0.0});          // thrown out: parked where it is
  engine.bodies[2] = at({kNaN, 0.0, 0.0});           // position lost: parked at the escape distance on +x
  engine.bodies[3] = at({0.0, 0.0, 1.0});
  engine.bodies[3].velocity_mps.z() = std::numeric_limits<double>::infinity();  // in range, velocity not finite
  engine.bodies[4] = at({far_m, 0.0, 0.0});
  engine.bodies[4].orientation_wxyz[2] = kNaN;      // its orientation is reset too
  // Object 5 is not simulated (static, or asleep outside the solver): never asked about further.
  EscapeGuard guard(6);
  guard.check_all(engine);
  CHECK(guard.escaped() == std::vector<std::size_t>{1, 2, 3, 4});
  CHECK_FALSE(guard.escaped(0));
  CHECK_FALSE(guard.escaped(5));
  CHECK(engine.parked.at(1).first == Eigen::Vector3d(0.0, far_m, 0.0));
  CHECK(engine.parked.at(2).first == Eigen::Vector3d(impetus::kEscapeDistance_m, 0.0, 0.0));
  CHECK(engine.parked.at(3).first == Eigen::Vector3d(0.0, 0.0, 1.0));
  CHECK_FALSE(engine.parked.at(1).second);
  CHECK(engine.parked.at(4).second);
  // Checked again, an escaped body is not parked again nor listed twice.
  engine.parked.clear();
  const std::size_t candidates[] = {1, 4, 0};
  guard.check(candidates, engine);
  CHECK(engine.parked.empty());
  CHECK(guard.escaped().size() == 4);
}
