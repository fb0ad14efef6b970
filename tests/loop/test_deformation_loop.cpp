// SPDX-License-Identifier: Apache-2.0
// A deformable slab in the whole loop (world, haptic side, device in one process; scenes/clay.json): the hard cases
// of a plastic surface. The phase experiment itself is scripts/deformation_experiment.py (its own CTest test).

#include "loop/in_process_trial.h"
#include "tests/integration/csv_columns.h"
#include "tests/integration/trial_support.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace impetus {
namespace {

const std::string kClay = std::string(IMPETUS_SOURCE_DIR) + "/scenes/clay.json";
constexpr double kSurface_m = 0.03;     // the clay's top face
constexpr double kThickness_m = 0.03;

nlohmann::json trial(const std::filesystem::path& dir, const std::vector<std::string>& fingers) {
  InProcessTrialOptions options;
  options.scene_path = kClay;
  if (fingers.size() == 1) {
    options.trajectory = fingers[0];
  } else {
    options.fingers = fingers;
  }
  options.out_dir = dir;
  return run_in_process_trial(options);
}

std::string press(double x_m, double depth_m, double hold_s, double speed_mps = 0.1) {
  return "press:x=" + std::to_string(x_m) + ",surface_z=" + std::to_string(kSurface_m) + ",depth=" +
         std::to_string(depth_m) + ",hold=" + std::to_string(hold_s) + ",speed=" + std::to_string(speed_mps);
}

const nlohmann::json& clay(const nlohmann::json& summary) { return summary["world"]["deformable"]["clay"]; }

TEST_CASE("clay pressed below its yield force for 10 s keeps no mark at all") {
  // Arriving at 1 cm/s, so the touch itself stays below yield too.
  const nlohmann::json summary = trial(test::out_dir("clay-light-press"), {press(0.0, 1e-3, 10.0, 0.01)});
  // The press stays below the yield force σ_y·π·a² = 5 kPa · π · (6 mm)² = 0.565 N the whole time...
  const double max_force_N = summary["haptic"]["endpoints"][0]["max_force_N"].get<double>();
  REQUIRE(max_force_N > 0.05);
  REQUIRE(max_force_N < 5000.0 * M_PI * 0.006 * 0.006);
  // ...so nothing yields: no creep, however long.
  CHECK(clay(summary)["absorbed_Ns"].get<double>() > 1.0);
  CHECK(clay(summary)["yielding_Ns"].get<double>() == 0.0);
  CHECK(clay(summary)["max_dent_m"].get<double>() == 0.0);
}

TEST_CASE("clay pressed far beyond its yield stays finite and keeps its last tenth: no hole through the slab") {
  // The hand's target 4 cm below the clay's face, 1 cm into the table, for 4 s: 12 N at first (the device's 10 N
  // limit), about 4 N on what is left.
  const std::filesystem::path dir = test::out_dir("clay-hard-press");
  const nlohmann::json summary = trial(dir, {press(0.0, 0.04, 4.0)});
  const double dent_m = clay(summary)["max_dent_m"].get<double>();
  CHECK(std::isfinite(dent_m));
  CHECK(dent_m == Approx(0.9 * kThickness_m));
  CHECK(clay(summary)["clamped_m3"].get<double>() > 0.0);
  const double volume_m3 = clay(summary)["dent_volume_m3"].get<double>();
  CHECK(std::isfinite(volume_m3));
  // The law's own check, less what the floor refused.
  CHECK((volume_m3 + clay(summary)["clamped_m3"].get<double>()) * 1e6 ==
        Approx(clay(summary)["yielding_Ns"].get<double>()).epsilon(1e-9));
  // The finger rests on the clay left (3 mm), not below it, to the end of the hold (the last row: the trajectory has
  // ended and the finger is gone).
  const auto columns = test::read_csv_columns(dir / "haptic.csv");
  const std::vector<double>& proxy_z = columns.at("proxy_z_m");
  REQUIRE(proxy_z.size() > 2);
  CHECK(proxy_z[proxy_z.size() - 2] == Approx(kSurface_m - 0.9 * kThickness_m).margin(1e-5));
}

TEST_CASE("two fingers on one slab each make the dent one finger makes alone") {
  const std::string a = press(-0.04, 0.006, 1.0);
  const std::string b = press(0.04, 0.006, 1.0);
  const nlohmann::json alone = trial(test::out_dir("clay-one-finger"), {a});
  const nlohmann::json both = trial(test::out_dir("clay-two-fingers"), {"a=" + a, "b=" + b});
  const double one_m3 = clay(alone)["dent_volume_m3"].get<double>();
  REQUIRE(one_m3 > 1e-8);  // a real dent (10 mm³)
  // 8 cm apart, their pads (6 mm) never meet: the mirrored presses dent alike, to rounding.
  CHECK(clay(both)["dent_volume_m3"].get<double>() == Approx(2.0 * one_m3).epsilon(1e-9));
  CHECK(clay(both)["max_dent_m"].get<double>() == Approx(clay(alone)["max_dent_m"].get<double>()).epsilon(1e-9));
}

}  // namespace
}  // namespace impetus
