// SPDX-License-Identifier: Apache-2.0
// A world that restarts mid-contact (docs/architecture.md §6: impulse rendered == impulse applied, across a restart of
// either side), deterministically: the servo and two worlds in this thread. The finger presses the cube of the tap
// scene from above; at 0.6 s the first world is gone and a fresh one (a new world session, the cube back where the
// scene puts it) takes its place. The new world must apply only what was rendered against its own frames — not the
// running total the finger built up against the dead world (which, applied at once, threw the cube off at hundreds
// of m/s).

#include "haptic_controller/servo.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <memory>
#include <string>

namespace impetus {
namespace {

constexpr double kTick_s = 1e-3;
constexpr int kTicksPerStep = 50;      // 1 kHz servo, the scene's 20 Hz world
constexpr int kRestartTick = 600;      // the press has held the cube for about 0.4 s by then
constexpr int kLastTick = 1500;

// Above the cube's top face (z = 0.05), then 1 cm into it by 0.2 s, held.
FingerSample finger_at(double t_s) {
  FingerSample sample;
  const double depth_m = std::min(t_s / 0.2, 1.0) * 0.02;
  sample.position_m = Eigen::Vector3d(0.03, 0.0, 0.06 - depth_m);
  sample.valid = true;
  return sample;
}

void check_restart(Coupling coupling) {
  prepare_engines();
  const Scene scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json");
  WorldOptions options;
  options.coupling = coupling;
  options.world_session = 11;
  auto world = std::make_unique<World>(scene, options);
  HapticServo servo(ServoOptions{}, 99);

  bool adopted = false;
  double fastest_after_restart_mps = 0.0;
  for (int tick = 0; tick <= kLastTick; ++tick) {
    const double now_s = tick * kTick_s;
    const FingerSample finger = finger_at(now_s);
    servo.tick(&finger, now_s, kTick_s);
    if (tick == kRestartTick) {
      options.world_session = 12;  // the world manager was killed and started again
      world = std::make_unique<World>(scene, options);
    }
    if (tick % kTicksPerStep != 0) continue;
    const PlaneFrame& frame = world->step(&servo.report());
    if (tick >= kRestartTick) {
      fastest_after_restart_mps = std::max(fastest_after_restart_mps, world->states()[0].velocity_mps.norm());
    }
    servo.on_plane_frame(frame, now_s);
    if (tick >= kRestartTick && !adopted) {
      adopted = true;  // the totals restart with the new world's first frame
      REQUIRE(servo.report().world_session == 12);
      REQUIRE(servo.report().entry_count == 0);
    }
  }
  // The impulse rendered against the first world is accounted for, not applied to the second.
  CHECK(servo.accumulator().abandoned_impulse_Ns().z() < -0.5);
  // The second world applied the cube's running total as of its last step (tick kLastTick, after the servo's tick),
  // which counts from the adoption: a sum of differences of one running total, equal up to rounding.
  const HapticReport& report = servo.report();
  REQUIRE(report.entry_count == 1);
  const Eigen::Vector3d rendered_Ns = to_eigen(report.entries[0].impulse_Ns);
  INFO("second world applied " << world->total_impulse_Ns(0).transpose() << ", rendered since adoption "
                               << rendered_Ns.transpose());
  CHECK(rendered_Ns.z() < -0.5);  // the finger kept pressing the new world's cube
  CHECK((world->total_impulse_Ns(0) - rendered_Ns).norm() < 1e-12);
  // Pressed onto the floor, the new cube barely moves (before the fix it left at hundreds of m/s).
  CHECK(fastest_after_restart_mps < 0.05);
}

}  // namespace

TEST_CASE("a restarted world applies only the impulse rendered against its own frames (impulse coupling)") {
  check_restart(Coupling::impulse);
}

TEST_CASE("a restarted world applies only the impulse rendered against its own frames (local coupling)") {
  check_restart(Coupling::local);
}

}  // namespace impetus

namespace impetus {
namespace {

// The clay (scenes/clay.json) pressed 2 mm into its face from 0.1 s on, held; the world restarts at 0.6 s. The new
// world starts from the scene (no dent) and dents by what was pushed against its own frames only.
// A finger pressed 2 mm into a deformable slab's face (`scene_file`, its top at 3 cm) from 0.1 s on, held; the world
// restarts at 0.6 s. What the new world and the servo hold at the end, and what the first world had taken.
struct Restarted {
  Scene scene;
  std::unique_ptr<World> world;
  HapticReport report;
  double first_world_yielding_Ns = 0.0;
};
Restarted restarted_mid_press(const std::string& scene_file) {
  prepare_engines();
  Restarted out;
  out.scene = load_scene(std::string(IMPETUS_SOURCE_DIR) + "/scenes/" + scene_file);
  WorldOptions options;
  options.world_session = 21;
  out.world = std::make_unique<World>(out.scene, options);
  HapticServo servo(ServoOptions{}, 98);
  const auto finger_at = [](double t_s) {
    FingerSample sample;
    sample.position_m = Eigen::Vector3d(0.0, 0.0, 0.035 - std::min(t_s / 0.1, 1.0) * 0.007);
    sample.valid = true;
    return sample;
  };
  for (int tick = 0; tick <= kLastTick; ++tick) {
    const double now_s = tick * kTick_s;
    const FingerSample finger = finger_at(now_s);
    servo.tick(&finger, now_s, kTick_s);
    if (tick == kRestartTick) {
      out.first_world_yielding_Ns = out.world->deformable(0)->yielding_Ns();
      options.world_session = 22;
      out.world = std::make_unique<World>(out.scene, options);
    }
    if (tick % kTicksPerStep != 0) continue;
    servo.on_plane_frame(out.world->step(&servo.report()), now_s);
  }
  out.report = servo.report();
  return out;
}

TEST_CASE("a restarted world dents clay only by the push given against its own frames") {
  const Restarted run = restarted_mid_press("clay.json");
  REQUIRE(run.first_world_yielding_Ns > 0.01);  // the first world was dented
  const DeformableSurface& clay = *run.world->deformable(0);
  REQUIRE(run.report.world_session == 22);
  REQUIRE(run.report.entry_count == 1);
  // The new world took exactly the push beyond yield rendered since its first frame (a sum of differences of one
  // running total, equal up to rounding), and its dent is that push over the flow resistance: nothing of the dead
  // world's push, whose running total was abandoned.
  CHECK(run.report.entries[0].press_Ns > 0.01);
  CHECK(clay.yielding_Ns() == Approx(run.report.entries[0].press_Ns).epsilon(1e-12));
  CHECK(clay.dent_volume_m3() * run.scene.objects[0].deformable->flow_resistance_Paspm ==
        Approx(clay.yielding_Ns()).epsilon(1e-12));
}

TEST_CASE("a restarted world moves a gel only by the push given against its own frames, and its books balance") {
  const Restarted run = restarted_mid_press("gel.json");
  REQUIRE(run.first_world_yielding_Ns > 0.01);
  const DeformableSurface& gel = *run.world->deformable(0);
  REQUIRE(run.report.world_session == 22);
  REQUIRE(run.report.entry_count == 1);
  // The new gel was pushed by exactly what was rendered against its frames, once.
  CHECK(run.report.entries[0].press_Ns > 0.01);
  CHECK(gel.yielding_Ns() == Approx(run.report.entries[0].press_Ns).epsilon(1e-12));
  // It holds the press, and its energy books balance across the restart: nothing of the dead world's came in.
  CHECK(gel.dent_m() > 0.0);
  CHECK(gel.work_J() + gel.scheme_J() == Approx(gel.dissipated_J() + gel.stored_J()).epsilon(1e-9));
  CHECK(gel.scheme_J() <= 1e-12 * gel.work_J());
}

}  // namespace
}  // namespace impetus
