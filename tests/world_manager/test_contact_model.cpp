// SPDX-License-Identifier: Apache-2.0
// The contact models (scene.h PhysicsParams): as a spring and a damper, a resting body sinks as deep at any substep;
// with ODE's per-substep ERP and CFM (the default) it sinks deeper at coarse substeps: the contact's stiffness is
// ERP/(h·CFM).
#include "world_test_support.h"

#include <catch2/catch.hpp>

#include <span>

namespace impetus {
namespace {

// How deep a 1 kg, 5 cm box rests in the floor after 2 s, with the world split into `substeps` per 20 Hz period.
double resting_depth_m(int substeps, const nlohmann::json& physics) {
  nlohmann::json document{
      {"physics", physics},
      {"objects",
       {{{"name", "box"}, {"shape", "box"}, {"size_m", {0.05, 0.05, 0.05}}, {"dynamic", true}, {"mass_kg", 1.0},
         {"position_m", {0.0, 0.0, 0.025}}}}}};
  document["physics"]["substeps"] = substeps;
  document["physics"]["auto_disable"] = false;  // the depth of the simulated body, not of one put to sleep
  const Scene scene = parse_scene(document, "contact.json");
  auto world = test::make_world(scene);
  for (int step = 0; step < 40; ++step) world->step(std::span<const HapticReport* const>{});
  return 0.025 - world->states()[0].pose.position_m.z();
}

}  // namespace

TEST_CASE("a body rests as deep at 5 ms and at 1 ms substeps with the spring and damper, not with ODE's own numbers") {
  const nlohmann::json spring{{"contact_stiffness_Npm", 4e6}, {"contact_damping_Nspm", 8e4}};
  const double coarse_m = resting_depth_m(10, spring), fine_m = resting_depth_m(50, spring);
  INFO("spring and damper: " << coarse_m * 1e6 << " um at 5 ms, " << fine_m * 1e6 << " um at 1 ms");
  CHECK(coarse_m > 0.0);
  CHECK(coarse_m < 10e-6);  // m·g over the box's contacts' springs: microns
  CHECK(fine_m == Approx(coarse_m).epsilon(0.02));
  // ODE's numbers as they are (the default, which the spring matches at 5 ms): five times stiffer at 1 ms.
  const nlohmann::json ode = nlohmann::json::object();
  const double ode_coarse_m = resting_depth_m(10, ode), ode_fine_m = resting_depth_m(50, ode);
  INFO("ODE's numbers: " << ode_coarse_m * 1e6 << " um at 5 ms, " << ode_fine_m * 1e6 << " um at 1 ms");
  CHECK(ode_coarse_m == Approx(coarse_m).epsilon(1e-9));
  CHECK(ode_fine_m == Approx(coarse_m / 5).epsilon(0.05));
}

}  // namespace impetus
