// SPDX-License-Identifier: Apache-2.0
// Several endpoints on one world (docs/architecture.md §1, §6), deterministically: a world and one servo per finger in
// this thread, the fingers on scripted paths (kinematic: the device holds them exactly where the script says, so what
// is tested is the world and the servos, not a hand model).
//   - Grasp and lift: thumb and index squeeze the grasp scene's cube from opposite sides, lift it 5 cm, hold 5 s and
//     put it down. Friction alone holds it.
//   - Two users, one cube: two haptic sessions push the tap scene's cube from opposite sides, equally (it stays) and
//     unequally (it moves as the net impulse says).
// In all of them each endpoint's impulse, as the world applied it, equals what its servo rendered.

#include "haptic_controller/servo.h"
#include "loop/in_process_trial.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace impetus {
namespace {

constexpr double kTick_s = 1e-3;
constexpr int kTicksPerStep = 50;  // 1 kHz servos, the scenes' 20 Hz world

// Servo ticks per world step at the scene's world rate.
int ticks_per_step(const Scene& scene) {
  return static_cast<int>(std::lround(1.0 / (scene.physics.world_rate_hz * kTick_s)));
}

Scene shipped_scene(const char* name) {
  return load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/" + name + ".json");
}

double smooth(double t_s, double begin_s, double end_s) {
  const double u = std::clamp((t_s - begin_s) / (end_s - begin_s), 0.0, 1.0);
  return 0.5 - 0.5 * std::cos(M_PI * u);
}

// One finger: its servo, its haptic session and endpoint, and where the script puts it at time t.
struct ScriptedFinger {
  std::unique_ptr<HapticServo> servo;
  std::function<Eigen::Vector3d(double)> path_m;
};

// What a run recorded, per world step.
struct Run {
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> cube_m;
  std::vector<Eigen::Vector3d> cube_velocity_mps;
  std::vector<double> finger_z_m;  // the first finger's height
  // Per finger: the report the world applied at its last step (rendered), and the world's per-endpoint total.
  std::vector<Eigen::Vector3d> rendered_Ns;
  std::vector<Eigen::Vector3d> applied_Ns;
  double max_force_N = 0.0;
};

// The world steps at ticks phase, phase + 50, ... (the lockstep phase, docs/architecture.md §3).
Run run(const Scene& scene, Coupling coupling, std::vector<ScriptedFinger>& fingers, double duration_s,
        int phase_ticks = 0) {
  prepare_engines();
  WorldOptions options;
  options.coupling = coupling;
  options.world_session = 7;
  World world(scene, options);
  Run out;
  std::vector<const HapticReport*> reports(fingers.size());
  std::vector<HapticReport> last_applied(fingers.size());
  // The haptic node exchanges pushes among its own endpoints; here, among the fingers of each session.
  std::vector<HapticServo*> servos;
  for (ScriptedFinger& finger : fingers) servos.push_back(finger.servo.get());
  const bool one_session = std::all_of(fingers.begin(), fingers.end(), [&](const ScriptedFinger& finger) {
    return finger.servo->report().haptic_session == fingers[0].servo->report().haptic_session;
  });
  if (!one_session) servos.clear();
  const int ticks = static_cast<int>(std::lround(duration_s / kTick_s));
  const int step_ticks = ticks_per_step(scene);
  for (int tick = 0; tick <= ticks; ++tick) {
    const double now_s = tick * kTick_s;
    for (ScriptedFinger& finger : fingers) {
      FingerSample sample;
      sample.position_m = finger.path_m(now_s);
      sample.valid = true;
      const TickResult& result = finger.servo->tick(&sample, now_s, kTick_s);
      out.max_force_N = std::max(out.max_force_N, to_eigen(result.force_N).norm());
    }
    exchange_pushes(servos);  // the fingers of one controller (one session) feel each other's pushes
    if (tick % step_ticks != phase_ticks) continue;
    for (std::size_t k = 0; k < fingers.size(); ++k) {
      reports[k] = &fingers[k].servo->report();
      last_applied[k] = fingers[k].servo->report();
    }
    const auto frames = world.step(reports);
    for (std::size_t k = 0; k < fingers.size(); ++k) fingers[k].servo->on_plane_frame(frames[k], now_s);
    out.time_s.push_back(world.time_s());
    out.cube_m.push_back(world.states()[0].pose.position_m);
    out.cube_velocity_mps.push_back(world.states()[0].velocity_mps);
    out.finger_z_m.push_back(fingers[0].path_m(now_s).z());
  }
  for (std::size_t k = 0; k < fingers.size(); ++k) {
    const HapticReport& report = last_applied[k];
    Eigen::Vector3d rendered = Eigen::Vector3d::Zero();
    for (std::uint32_t e = 0; e < report.entry_count; ++e) {
      if (report.entries[e].object_id == 0) rendered = to_eigen(report.entries[e].impulse_Ns);
    }
    out.rendered_Ns.push_back(rendered);
    out.applied_Ns.push_back(world.applied_by({report.haptic_session, report.endpoint}, 0));
  }
  return out;
}

void check_applied_equals_rendered(const Run& result) {
  for (std::size_t k = 0; k < result.rendered_Ns.size(); ++k) {
    INFO("endpoint " << k << ": rendered " << result.rendered_Ns[k].transpose() << " N·s, applied "
                     << result.applied_Ns[k].transpose());
    CHECK(result.rendered_Ns[k].norm() > 0.01);  // it really pushed
    CHECK((result.rendered_Ns[k] - result.applied_Ns[k]).norm() <= 1e-12 * (1.0 + result.rendered_Ns[k].norm()));
  }
}

// Index of the first step at or after t.
std::size_t step_at(const Run& result, double t_s) {
  return static_cast<std::size_t>(std::lower_bound(result.time_s.begin(), result.time_s.end(), t_s - 1e-9) -
                                  result.time_s.begin());
}

// Grasp and lift. The cube's sides are at x = ±0.025 m; each finger aims 1.25 mm inside its side, so the servo's
// spring (2 kN/m) squeezes with 2.5 N: friction (μ_s = 1.0) can hold up to 5 N against the cube's 1.96 N weight.
// Timeline (s): close 0–0.5, settle to 1, lift 5 cm over 1–2, hold 2–7, lower 7–8, open 8–8.5, rest to 9.
constexpr double kSqueeze_m = 0.00125;
constexpr double kLift_m = 0.05;

Eigen::Vector3d grasp_path(double side, double t_s) {
  const double open_x = side * 0.045;
  const double closed_x = side * (0.025 - kSqueeze_m);
  const double x = open_x + (closed_x - open_x) * (smooth(t_s, 0.0, 0.5) - smooth(t_s, 8.0, 8.5));
  const double z = 0.025 + kLift_m * (smooth(t_s, 1.0, 2.0) - smooth(t_s, 7.0, 8.0));
  return {x, 0.0, z};
}

// Returns the lift height.
double check_grasp(Coupling coupling, int phase_ticks = 0, const Scene& scene = shipped_scene("grasp")) {
  std::vector<ScriptedFinger> fingers;
  const std::uint64_t session = 42;
  fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, session, 0),
                     [](double t) { return grasp_path(-1.0, t); }});  // thumb, from −x
  fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, session, 1),
                     [](double t) { return grasp_path(+1.0, t); }});  // index, from +x
  const Run result = run(scene, coupling, fingers, 9.0, phase_ticks);

  // Lifted: at the start of the hold the cube is up with the fingers.
  const std::size_t hold_begin = step_at(result, 2.5);  // half a second after the lift, to let it settle
  const std::size_t hold_end = step_at(result, 7.0);
  const double lifted_m = result.cube_m[hold_begin].z() - 0.025;
  // Motion is measured from the poses, step to step (what the user sees and feels); the velocity the engine reports
  // at a step's end also holds the within-step sawtooth of impulses placed at their render times.
  double slip_m = 0.0, fastest_hold_mps = 0.0;
  for (std::size_t i = hold_begin; i <= hold_end; ++i) {
    slip_m = std::max(slip_m, (result.cube_m[i] - result.cube_m[hold_begin]).norm());
    if (i > hold_begin) {
      fastest_hold_mps = std::max(fastest_hold_mps, (result.cube_m[i] - result.cube_m[i - 1]).norm() /
                                                        (result.time_s[i] - result.time_s[i - 1]));
    }
  }
  const Eigen::Vector3d& final_m = result.cube_m.back();
  INFO(to_string(coupling) << " coupling: lifted " << lifted_m * 1e3 << " mm, slip during the hold " << slip_m * 1e3
                           << " mm, fastest during the hold " << fastest_hold_mps * 1e3 << " mm/s, ends at "
                           << final_m.transpose() << " m, largest force " << result.max_force_N << " N");
  // The cube follows the fingers up within the sag its weight needs: the proxies stick on its sides and their
  // springs stretch by weight / (2 k) ≈ 0.5 mm each, plus what the squeeze lets it settle.
  CHECK(lifted_m > kLift_m - 0.005);
  CHECK(lifted_m < kLift_m + 0.001);  // never thrown above the fingers
  CHECK(slip_m < 0.001);              // held by friction: < 1 mm of slip over 4.5 s
  CHECK(fastest_hold_mps < 0.01);
  // Put down where it was picked up, at rest.
  CHECK(std::abs(final_m.z() - 0.025) < 0.001);
  CHECK(std::abs(final_m.x()) < 0.005);
  CHECK((result.cube_m.back() - result.cube_m[result.cube_m.size() - 2]).norm() < 1e-5);  // at rest
  check_applied_equals_rendered(result);
  return lifted_m;
}

}  // namespace

// Impulse coupling cannot lift the grasped cube. The proxies stick to planes that move only with the world's frames,
// a period late; as the fingers rise, the sticking springs stretch until the next frame, and the period's impulse
// then exceeds what the cube needed (0.15 N·s against m·g·T = 0.10 N·s in the lift's first step): the cube is thrown
// up 12 mm, the fingers lose it, and slower lifts (2 and 3 s) fail alike. The loop through a period's delay has gain
// about 2·k·T²/m = 50 here. Not hidden: measured and printed, and the ledger's invariant still holds.
TEST_CASE("several endpoints under impulse coupling: a grasped cube is thrown by the period's support impulse, and "
          "each endpoint's impulse is still applied as rendered") {
  const Scene scene = shipped_scene("grasp");
  std::vector<ScriptedFinger> fingers;
  fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, 42, 0), [](double t) { return grasp_path(-1, t); }});
  fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, 42, 1), [](double t) { return grasp_path(+1, t); }});
  const Run result = run(scene, Coupling::impulse, fingers, 9.0);
  double highest_m = 0.0;
  for (const Eigen::Vector3d& cube_m : result.cube_m) highest_m = std::max(highest_m, cube_m.z());
  WARN("impulse coupling, grasp and lift: the cube rose to " << (highest_m - 0.025) * 1e3 << " mm and ends "
       << (result.cube_m.back() - Eigen::Vector3d(0, 0, 0.025)).norm() * 1e3 << " mm from where it started");
  CHECK(result.cube_m.back().allFinite());
  check_applied_equals_rendered(result);
}

// The same grasp under impulse coupling with the world at 200 Hz. The grip is a spring of 2·k on the cube, natural
// frequency ω = √(2·k/m) = 141 rad/s here; the cube answers a period's impulse a period later, so the loop keeps up
// only while ω·T is below about 1 (measured: 100 Hz, ω·T = 1.4, throws the cube; 150 Hz, 0.94, lifts it 43 mm with
// slip; 200 Hz, 0.71, lifts it as local coupling does at 20 Hz). This shows the failure at 20 Hz is the period's,
// not the ledger's or the servo's: the same code holds the cube once the period is short against the grip.
TEST_CASE("several endpoints under impulse coupling: with the world period short against the grip's natural period "
          "(200 Hz) the grasped cube is lifted, held and put down (every world phase)") {
  Scene scene = shipped_scene("grasp");
  scene.physics.world_rate_hz = 200.0;
  scene.physics.substeps = 1;  // the default 5 ms substep, as at 20 Hz × 10
  const double omega_T = std::sqrt(2.0 * scene.haptic.stiffness_Npm / scene.objects[0].mass_kg) /
                         scene.physics.world_rate_hz;
  REQUIRE(omega_T < 1.0);
  double lowest_m = 1.0, highest_m = 0.0;
  for (int phase = 0; phase < ticks_per_step(scene); ++phase) {
    const double lifted_m = check_grasp(Coupling::impulse, phase, scene);
    lowest_m = std::min(lowest_m, lifted_m);
    highest_m = std::max(highest_m, lifted_m);
  }
  WARN("impulse coupling, 200 Hz world (omega T = " << omega_T << "), grasp and lift over every phase: lifted "
       << lowest_m * 1e3 << " to " << highest_m * 1e3 << " mm");
}

TEST_CASE("several endpoints: thumb and index grasp a cube, lift it 5 cm, hold it by friction and put it down "
          "(local coupling, 5 world phases)") {
  double lowest_m = 1.0, highest_m = 0.0;
  for (int phase = 0; phase < kTicksPerStep; phase += kTicksPerStep / 5) {
    const double lifted_m = check_grasp(Coupling::local, phase);
    lowest_m = std::min(lowest_m, lifted_m);
    highest_m = std::max(highest_m, lifted_m);
  }
  WARN("local coupling, grasp and lift over 5 world phases: lifted " << lowest_m * 1e3 << " to " << highest_m * 1e3
       << " mm (the fingers rose " << kLift_m * 1e3 << " mm)");
}

TEST_CASE("several endpoints: two users push one cube, equally (it stays) and unequally (the net impulse moves it)") {
  const Scene scene = shipped_scene("tap");  // the 1 kg cube, sides at x = 0.005 and 0.055 m
  // User A pushes from −x, user B from +x, each its own haptic session; each presses `depth` into its side.
  auto push = [&](double depth_a_m, double depth_b_m) {
    std::vector<ScriptedFinger> fingers;
    fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, 101, 0), [=](double t) {
                         return Eigen::Vector3d(-0.01 + (0.015 + depth_a_m) * smooth(t, 0.0, 0.5), 0.0, 0.025);
                       }});
    fingers.push_back({std::make_unique<HapticServo>(ServoOptions{}, 202, 0), [=](double t) {
                         return Eigen::Vector3d(0.07 - (0.015 + depth_b_m) * smooth(t, 0.0, 0.5), 0.0, 0.025);
                       }});
    return run(scene, Coupling::impulse, fingers, 3.0);
  };
  SECTION("equal and opposite: the cube stays") {
    const Run result = push(0.001, 0.001);
    const double moved_m = std::abs(result.cube_m.back().x() - 0.03);
    INFO("moved " << moved_m * 1e3 << " mm");
    CHECK(moved_m < 0.001);
    check_applied_equals_rendered(result);
    // Each pushed about K·depth = 2 N for 2.5 s: the totals are opposite and near equal.
    CHECK(result.applied_Ns[0].x() > 3.0);
    CHECK(std::abs(result.applied_Ns[0].x() + result.applied_Ns[1].x()) < 0.05 * result.applied_Ns[0].x());
  }
  SECTION("unequal: the stronger push moves it, by the net impulse") {
    const Run result = push(0.004, 0.001);
    check_applied_equals_rendered(result);
    const double net_Ns = result.applied_Ns[0].x() + result.applied_Ns[1].x();
    const double moved_m = result.cube_m.back().x() - 0.03;
    INFO("net impulse " << net_Ns << " N·s, moved " << moved_m * 1e3 << " mm");
    CHECK(net_Ns > 0.5);
    CHECK(moved_m > 0.002);  // toward +x, the weaker user's side
  }
}

}  // namespace impetus

namespace impetus {
namespace {

// A finger that comes in along x from `from_x` to `to_x` over 0.5 s and holds until 12 s.
std::string squeeze_path(const std::filesystem::path& dir, const std::string& name, double from_x, double to_x) {
  const std::filesystem::path path = dir / (name + ".csv");
  std::ofstream out(path);
  out << "t,x,y,z\n0," << from_x << ",0,0.025\n0.5," << to_x << ",0,0.025\n24," << to_x << ",0,0.025\n";
  return path.string();
}

struct Squeeze {
  double largest_force_N = 0.0;
  // The largest peak-to-peak of the first finger's force in any whole second of 1–12 s, and of 12–24 s.
  double early_swing_N = 0.0;
  double late_swing_N = 0.0;
  double cube_moved_m = 0.0;
  double cube_speed_end_mps = 0.0;
  double model_error_max_m[2] = {0.0, 0.0};  // each endpoint's local model against the world's next frame
};

// The grasp scene's cube squeezed from both sides, 8 mm past each (about 2 N through the simulated hands), for 12 s:
// by one controller with two fingers (`one_controller`) or by two users, one finger each.
Squeeze squeeze(Coupling coupling, bool one_controller) {
  const std::string name = std::string("squeeze-") + to_string(coupling) + (one_controller ? "-one" : "-two");
  const std::filesystem::path dir = std::filesystem::path(IMPETUS_BINARY_DIR) / "test-out" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  InProcessTrialOptions options;
  options.scene_path = std::string(IMPETUS_SOURCE_DIR) + "/scenes/grasp.json";
  options.coupling = coupling;
  options.out_dir = dir;
  const std::string a = "a=" + squeeze_path(dir, "a", -0.045, -0.017);
  const std::string b = "b=" + squeeze_path(dir, "b", 0.045, 0.017);
  if (one_controller) {
    options.fingers = {a, b};
  } else {
    options.fingers = {a};
    options.followers = {{b}};
  }
  const nlohmann::json summary = run_in_process_trial(options);
  Squeeze out;
  const nlohmann::json& first = summary["haptic"]["endpoints"][0];
  const nlohmann::json& second =
      one_controller ? summary["haptic"]["endpoints"][1] : summary["followers"][0]["haptic"]["endpoints"][0];
  out.largest_force_N = std::max(first["max_force_N"].get<double>(), second["max_force_N"].get<double>());
  out.model_error_max_m[0] = first["local_model_error_max_m"].get<double>();
  out.model_error_max_m[1] = second["local_model_error_max_m"].get<double>();
  const auto& position = summary["objects"]["cube"]["position"];
  out.cube_moved_m = std::hypot(position[0].get<double>(), position[1].get<double>());
  const auto& velocity = summary["objects"]["cube"]["velocity"];
  out.cube_speed_end_mps =
      std::hypot(velocity[0].get<double>(), velocity[1].get<double>(), velocity[2].get<double>());
  // The first finger's force over time, from its log: time_s first, force_x the 9th column.
  std::ifstream log(dir / "haptic.csv");
  std::string line;
  std::getline(log, line);
  std::array<double, 24> low{}, high{};
  low.fill(1e9);
  high.fill(-1e9);
  while (std::getline(log, line)) {
    std::istringstream row(line);
    std::string cell;
    std::vector<double> values;
    while (std::getline(row, cell, ',')) values.push_back(std::stod(cell));
    const auto second = static_cast<std::size_t>(values[0]);
    if (second >= low.size()) continue;
    low[second] = std::min(low[second], values[8]);
    high[second] = std::max(high[second], values[8]);
  }
  for (std::size_t second = 1; second < 23; ++second) {
    double& swing = second < 12 ? out.early_swing_N : out.late_swing_N;
    swing = std::max(swing, high[second] - low[second]);
  }
  return out;
}

}  // namespace

// Pinch across users: each user's local model knows only its own push, so each lets the cube give way to it as if
// the other finger were not there; the world, which has both, holds the cube. The disagreement shows at each frame
// (local_model_error_max_m); what must hold is that it stays bounded and passive.
TEST_CASE("pinch across users: two controllers squeezing one cube keep bounded forces, no energy gain and no growing "
          "oscillation (impulse and local coupling), and the local models' disagreement is reported") {
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    const Squeeze two = squeeze(coupling, false);
    WARN(to_string(coupling) << " coupling, two users: largest force " << two.largest_force_N << " N, force swing "
                             << two.early_swing_N << " N (1-12 s) and " << two.late_swing_N << " N (12-23 s), cube moved "
                             << two.cube_moved_m * 1e3 << " mm");
    CHECK(two.largest_force_N < 5.0);            // about 2 N aimed: no spike
    // Not growing: the second 11 s half of the run swings no more than the first, where a growing cycle would.
    // Impulse coupling settles into a stationary cycle (its halves agree to 1e-5, hence the 0.1 %); local coupling
    // settles to rest, where a swing under 1 mN is rounding, far below the ~50 mN a fingertip can tell apart.
    CHECK((two.late_swing_N <= 1.001 * two.early_swing_N || two.late_swing_N < 1e-3));
    CHECK(two.cube_moved_m < 0.005);
    CHECK(two.cube_speed_end_mps < 0.005);       // at rest: no energy gained
    if (coupling == Coupling::local) {
      const Squeeze one = squeeze(coupling, true);
      WARN("local coupling, squeeze: each finger's model against the world's next frame, at most "
           << two.model_error_max_m[0] * 1e3 << " / " << two.model_error_max_m[1] * 1e3
           << " mm with two users (a model each), " << one.model_error_max_m[0] * 1e3 << " / "
           << one.model_error_max_m[1] * 1e3 << " mm with one controller of two fingers (pushes exchanged)");
      CHECK(one.model_error_max_m[0] <= two.model_error_max_m[0]);
    }
  }
}

}  // namespace impetus
