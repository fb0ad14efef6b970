// SPDX-License-Identifier: Apache-2.0
// An elastic slab in the whole loop (world, haptic side, device in one process; scenes/gel.json): what the finger
// feels at any world rate, the gel springing back, its energy books, and its floor. The phase experiment itself is
// scripts/deformation_experiment.py --scene scenes/gel.json (its own CTest test).

#include "loop/in_process_trial.h"
#include "tests/integration/csv_columns.h"
#include "tests/integration/trial_support.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace impetus {
namespace {

const std::string kGel = std::string(IMPETUS_SOURCE_DIR) + "/scenes/gel.json";
constexpr double kSurface_m = 0.03;  // the gel's top face
constexpr double kStiffness_Npm = 2000.0;  // the scene's haptic spring

nlohmann::json trial(const std::filesystem::path& dir, const std::string& trajectory, double rate_hz,
                     const std::vector<std::string>& fingers = {}) {
  InProcessTrialOptions options;
  options.scene_path = kGel;
  options.trajectory = trajectory;
  options.fingers = fingers;
  options.world_rate_hz = rate_hz;
  options.out_dir = dir;
  return run_in_process_trial(options);
}

const nlohmann::json& gel(const nlohmann::json& summary) { return summary["world"]["deformable"]["gel"]; }

struct Held {
  double force_N = 0.0;     // the mean push over the window
  double ripple_N = 0.0;    // its max − min
  double below_m = 0.0;     // the finger's mean depth below the undented face
  double world_dent_m = 0.0;  // the world's deepest cell at the window's end
};

// The last 0.3 s of a 1.2 s hold but its final 50 ms, of the finger that logs to `haptic_log`.
Held held(const std::filesystem::path& dir, const std::string& haptic_log = "haptic.csv") {
  const auto haptic = test::read_csv_columns(dir / haptic_log);
  const auto world = test::read_csv_columns(dir / "world.csv");
  const std::vector<double>& time_s = haptic.at("time_s");
  REQUIRE(time_s.size() > 100);
  const double end_s = time_s.back() - 0.05;
  const double start_s = end_s - 0.3;
  Held out;
  double low_N = 1e9, high_N = -1e9;
  int count = 0;
  for (std::size_t k = 0; k < time_s.size(); ++k) {
    if (time_s[k] < start_s || time_s[k] > end_s) continue;
    const double force_N = haptic.at("force_z_N")[k];
    out.force_N += force_N;
    out.below_m += kSurface_m - haptic.at("finger_z_m")[k];
    low_N = std::min(low_N, force_N);
    high_N = std::max(high_N, force_N);
    ++count;
  }
  REQUIRE(count > 100);
  out.force_N /= count;
  out.below_m /= count;
  out.ripple_N = high_N - low_N;
  const std::vector<double>& world_time_s = world.at("time_s");
  for (std::size_t k = 0; k < world_time_s.size() && world_time_s[k] <= end_s; ++k) {
    out.world_dent_m = world.at("gel.dent_m")[k];
  }
  return out;
}

TEST_CASE("a finger pressing the gel feels the spring and the gel in series, the same at 1 kHz, 20 and 10 Hz") {
  const std::string press = "press:x=0,y=0,surface_z=" + std::to_string(kSurface_m) + ",depth=0.006,hold=1.2";
  double reference_N = 0.0;
  double reference_ripple_N = 0.0;
  for (const double rate_hz : {1000.0, 20.0, 10.0}) {
    INFO("world at " << rate_hz << " Hz");
    const std::filesystem::path dir = test::out_dir("gel-press-" + std::to_string(static_cast<int>(rate_hz)));
    const nlohmann::json summary = trial(dir, press, rate_hz);
    const double compliance_mpN = gel(summary)["compliance_mpN"].get<double>();
    REQUIRE(compliance_mpN > 0.0);
    const Held h = held(dir);
    // The spring k and the gel's compliance c in series (haptic_controller/local_yield.h): F = k·p / (1 + c·k), p
    // how far the finger is below the face. To 3 %: the patch the world sends is flat to the static response's
    // window, a few µm under a 5 mm dent, which the stiff spring turns into a few hundredths of a newton.
    const double ck = compliance_mpN * kStiffness_Npm;
    CHECK(h.force_N == Approx(kStiffness_Npm * h.below_m / (1.0 + ck)).epsilon(0.03));
    // It holds still: no ringing of a delayed spring against the gel. The 1 kHz run's ripple is the device's own
    // (its encoders' counts through the spring); the slower worlds add nothing to it.
    if (rate_hz == 1000.0) reference_ripple_N = h.ripple_N;
    CHECK(h.ripple_N <= reference_ripple_N + 1e-9);
    // The world's gel sits where the haptic side put it: c·F under the finger.
    CHECK(h.world_dent_m == Approx(compliance_mpN * h.force_N).epsilon(0.03));
    if (rate_hz == 1000.0) {
      reference_N = h.force_N;
    } else {
      CHECK(h.force_N == Approx(reference_N).epsilon(0.01));
    }
  }
}

TEST_CASE("two fingers on the gel each feel and make what one finger alone does, at 10 Hz") {
  // 6 cm apart (30 of the gel's decay lengths): neither dent reaches the other finger. Each finger's frame leaves out
  // its own share and shows the other's, so each feels the same as alone: were its own share shown, it would feel
  // its own dent a period late on top of the one the haptic side renders.
  const auto press = [](double x_m) {
    return "press:x=" + std::to_string(x_m) + ",y=0,surface_z=" + std::to_string(kSurface_m) + ",depth=0.006,hold=1.2";
  };
  const std::filesystem::path alone_dir = test::out_dir("gel-one-finger");
  const std::filesystem::path both_dir = test::out_dir("gel-two-fingers");
  const nlohmann::json alone = trial(alone_dir, press(-0.03), 10.0);
  const nlohmann::json both = trial(both_dir, "", 10.0, {"a=" + press(-0.03), "b=" + press(0.03)});
  const Held one = held(alone_dir);
  const Held first = held(both_dir, "haptic.csv");
  const Held second = held(both_dir, "haptic.endpoint1.csv");
  REQUIRE(one.force_N > 0.3);
  CHECK(first.force_N == Approx(one.force_N).epsilon(1e-6));
  CHECK(second.force_N == Approx(one.force_N).epsilon(1e-6));
  // The world's gel holds both dents, each as deep as the one alone.
  CHECK(first.world_dent_m == Approx(one.world_dent_m).epsilon(1e-6));
  CHECK(gel(both)["max_dent_m"].get<double>() == Approx(gel(alone)["max_dent_m"].get<double>()).epsilon(1e-6));
}

TEST_CASE("the gel springs back flat once the finger leaves, and its energy books balance") {
  for (const double rate_hz : {20.0, 10.0}) {
    INFO("world at " << rate_hz << " Hz");
    const std::filesystem::path dir = test::out_dir("gel-release-" + std::to_string(static_cast<int>(rate_hz)));
    // Down 5 mm into the gel at 0.1 m/s, held 0.5 s, out, and 0.6 s above it.
    const std::filesystem::path path = dir / "press_release.csv";
    std::filesystem::create_directories(dir);
    std::ofstream(path) << "t,x,y,z\n0,0,0,0.05\n0.2,0,0,0.05\n0.45,0,0,0.025\n0.95,0,0,0.025\n1.2,0,0,0.05\n"
                           "1.8,0,0,0.05\n";
    const nlohmann::json summary = trial(dir, path.string(), rate_hz);
    const nlohmann::json& g = gel(summary);
    CHECK(g["max_dent_m"].get<double>() > 2e-3);
    CHECK(g["dent_m"].get<double>() < 1e-9);
    const double work_J = g["work_J"].get<double>();
    REQUIRE(work_J > 0.0);
    // Everything the pushes did went to damping or is still held, with the integrator's own share counted apart
    // (deform/elastic_membrane.h): never a gain (but for the last substep's, waiting to be given back), and what its
    // observer gave back, the skin's lag over a substep, a few per cent of the work (4.5 to 6 % measured at two
    // substeps a radian; a tenth would mean the substeps were too coarse). The gel holds nearly nothing at rest.
    const double unbalanced_J = work_J + g["scheme_J"].get<double>() - g["dissipated_J"].get<double>() -
                                g["stored_J"].get<double>();
    CHECK(std::abs(unbalanced_J) < 1e-9 * work_J);
    CHECK(g["scheme_J"].get<double>() <= 1e-12 * work_J);
    CHECK(g["given_back_J"].get<double>() < 0.1 * work_J);
    CHECK(g["stored_J"].get<double>() < 1e-6 * work_J);
    // The push reached the world whole: what the haptic side rendered into the gel is what moved it (to the cosine
    // of the patch's slight tilt: the push is counted along the surface under the finger, absorbed along the face).
    CHECK(g["yielding_Ns"].get<double>() == Approx(g["absorbed_Ns"].get<double>()).epsilon(1e-3));
  }
}

TEST_CASE("gel stroked fast (0.5 m/s, 4 cm a 10 Hz period): finite, nothing lost, felt as at 1 kHz") {
  const std::string slide = "slide:x=-0.04,y=0,surface_z=" + std::to_string(kSurface_m) +
                            ",depth=0.005,distance=0.08,speed=0.5";
  const std::filesystem::path reference_dir = test::out_dir("gel-fast-stroke-1000");
  const std::filesystem::path stroked_dir = test::out_dir("gel-fast-stroke-10");
  const nlohmann::json reference = gel(trial(reference_dir, slide, 1000.0));
  const nlohmann::json stroked = gel(trial(stroked_dir, slide, 10.0));
  REQUIRE(reference["yielding_Ns"].get<double>() > 0.1);
  CHECK(std::isfinite(stroked["max_dent_m"].get<double>()));
  CHECK(stroked["max_dent_m"].get<double>() > 1e-3);
  CHECK(stroked["lost_Ns"].get<double>() == 0.0);
  const double work_J = stroked["work_J"].get<double>();
  CHECK(std::abs(work_J + stroked["scheme_J"].get<double>() - stroked["dissipated_J"].get<double>() -
                 stroked["stored_J"].get<double>()) < 1e-9 * work_J);
  // One finger feels the gel through the haptic side's model alone (its frame's patch is the face: the gel is all its
  // own share), so its force is the 1 kHz run's, tick for tick, however far it goes in a period. (The pushes the
  // worlds took differ by the last period's, still in flight when the trial ends with the finger down.)
  const auto at_10_Hz = test::read_csv_columns(stroked_dir / "haptic.csv");
  const auto at_1_kHz = test::read_csv_columns(reference_dir / "haptic.csv");
  const std::vector<double>& world_10_Hz_N = at_10_Hz.at("force_z_N");
  const std::vector<double>& world_1_kHz_N = at_1_kHz.at("force_z_N");
  REQUIRE(world_10_Hz_N.size() == world_1_kHz_N.size());
  double largest_N = 0.0;
  for (std::size_t k = 0; k < world_10_Hz_N.size(); ++k) {
    largest_N = std::max(largest_N, std::abs(world_10_Hz_N[k] - world_1_kHz_N[k]));
  }
  CHECK(largest_N < 1e-9);
}

TEST_CASE("gel pressed far beyond what it holds stops at its floor: finite, no hole, the stopped speed counted") {
  // The hand's target 4 cm below the face, 1 cm into the table: the spring and gel in series would sink the gel's
  // centre 36 mm, beyond its 27 mm of travel.
  const std::filesystem::path dir = test::out_dir("gel-hard-press");
  const nlohmann::json summary =
      trial(dir, "press:x=0,y=0,surface_z=" + std::to_string(kSurface_m) + ",depth=0.04,hold=2", 10.0);
  const double dent_m = gel(summary)["max_dent_m"].get<double>();
  CHECK(std::isfinite(dent_m));
  CHECK(dent_m == Approx(0.9 * 0.03));
  CHECK(std::isfinite(gel(summary)["work_J"].get<double>()));
  const auto haptic = test::read_csv_columns(dir / "haptic.csv");
  const std::vector<double>& proxy_z = haptic.at("proxy_z_m");
  // The finger rests on the 3 mm the floor keeps, never below.
  CHECK(*std::min_element(proxy_z.begin(), proxy_z.end()) > kSurface_m - 0.9 * 0.03 - 1e-4);
}

}  // namespace
}  // namespace impetus
