// SPDX-License-Identifier: Apache-2.0
// Objects too light for impulse coupling at a world rate (world_manager/impulse_limits.h).

#include "world_manager/impulse_limits.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

TEST_CASE("impulse limits: objects a period's push at the device limit would throw faster than a hand are listed") {
  const impetus::Scene scene = impetus::parse_scene(
      nlohmann::json{{"objects",
                      {{{"name", "cube"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true},
                        {"mass_kg", 1.0}, {"position_m", {0, 0, 0.025}}},
                       {{"name", "ball"}, {"shape", "sphere"}, {"radius_m", 0.01}, {"dynamic", true},
                        {"mass_kg", 0.0029}, {"position_m", {0.1, 0, 0.01}}},
                       {{"name", "bead"}, {"shape", "sphere"}, {"radius_m", 0.005}, {"dynamic", true},
                        {"mass_kg", 0.001}, {"position_m", {-0.1, 0, 0.005}}},
                       {{"name", "wall"}, {"shape", "box"}, {"size_m", {0.01, 0.2, 0.05}}, {"dynamic", false},
                        {"position_m", {0.2, 0, 0.025}}}}}},
      "light.json");
  // 20 Hz, 10 N: the 1 kg cube would reach 0.5 m/s (fine), the 2.9 g ball 172 m/s, the 1 g bead 500 m/s.
  const impetus::LightObjects light = impetus::light_for_impulse_coupling(scene, 0.05, 10.0);
  CHECK(light.count == 2);
  CHECK(light.lightest_name == "bead");
  CHECK(light.lightest_speed_mps == Approx(500.0));
  // At 1 kHz a period's push gives the ball 3.4 m/s, the bead 10 m/s: still over a hand's 2 m/s; the cube never.
  CHECK(impetus::light_for_impulse_coupling(scene, 0.001, 10.0).count == 2);
  CHECK(impetus::light_for_impulse_coupling(scene, 0.0001, 10.0).count == 0);
}
