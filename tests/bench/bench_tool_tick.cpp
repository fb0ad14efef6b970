// SPDX-License-Identifier: Apache-2.0
// Tick cost of a rigid tool's 6-DoF god-object (haptic_controller/tool/tool_proxy.h) among 16 objects (boxes, balls,
// capsules, a cylinder and the floor), the hand holding the grip while its target wanders and turns through them,
// for a box peg and a capsule probe: p50 / p99 / max in ns, how often it touched, the contacts and passes a tick.
// Beside it, in the same run, the point finger's servo tick (HapticServo::tick) at the peg's tip on the hand's target
// among the same objects. Then a peg striking a free cube, and a hand levering a box over a ledge, against the world
// at several rates and couplings (tests/support/tool_strike.h), against the 1 kHz world. Then the closed loop's
// stability (the hand pressing the cube tool into a corner through lagging motors, tests/support/tool_scenes.h): the
// loop's energy at the end over at the start, and its largest rise in a tick, over coupling stiffness, motor lag and
// the dampers. Prints only; no assertions. `--ticks N` sets the ticks per tool (default 20000).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "haptic_controller/servo.h"
#include "haptic_controller/tool/tool_proxy.h"
#include "tests/support/tool_scenes.h"
#include "tests/support/tool_strike.h"

using namespace impetus;
using impetus::test::pose_at;

namespace {

constexpr int kTicksPerWorldStep = 50;  // 1 kHz servo, 20 Hz world

// Plays the hand against the tool among the clutter, timing each solve.
void run_tool(const char* name, const ToolShape& tool, const Eigen::Vector3d& offset_m, int ticks) {
  const PlaneSet planes = impetus::test::clutter();
  ToolProxy proxy(tool, ToolCoupling{});
  std::vector<double> ns(static_cast<std::size_t>(ticks));
  int contact_ticks = 0, active_sum = 0, active_max = 0, passes_max = 0, constraints_max = 0;
  std::chrono::steady_clock::time_point start;
  impetus::test::wander(proxy, planes, offset_m, ticks, [&] { start = std::chrono::steady_clock::now(); },
                        [&](int tick, const BodyPose&, const ToolResult& result) {
    const auto stop = std::chrono::steady_clock::now();
    ns[static_cast<std::size_t>(tick)] = std::chrono::duration<double, std::nano>(stop - start).count();
    if (result.active > 0) {
      ++contact_ticks;
      active_sum += result.active;
    }
    active_max = std::max(active_max, result.active);
    passes_max = std::max(passes_max, result.passes);
    constraints_max = std::max(constraints_max, result.constraints);
  });
  std::sort(ns.begin(), ns.end());
  std::printf("tool %-15s 16 objects  tick p50 %6.0f ns  p99 %6.0f ns  max %8.0f ns  (contact %4.1f%% of ticks, "
              "%.1f acting contacts on average, at most %d; at most %d passes, %d constraints; %llu pinches, %llu "
              "unconverged)\n",
              name, ns[ns.size() / 2], ns[ns.size() * 99 / 100], ns.back(), 100.0 * contact_ticks / ticks,
              contact_ticks > 0 ? static_cast<double>(active_sum) / contact_ticks : 0.0, active_max, passes_max,
              constraints_max, static_cast<unsigned long long>(proxy.counters().pinches),
              static_cast<unsigned long long>(proxy.counters().unconverged));
}

// The world's frame for a point finger at `finger_m`: each object's plane at its point nearest the finger.
PlaneFrame frame_for(const PlaneSet& planes, const Eigen::Vector3d& finger_m, std::uint64_t index) {
  PlaneFrame frame;
  frame.frame_index = index;
  frame.world_session = 1;
  frame.world_period_s = kTicksPerWorldStep * 1e-3;
  frame.stiffness_Npm = 2000.0;
  for (std::uint32_t j = 0; j < planes.count; ++j) {
    const ContactPlane& object = planes.planes[j];
    Plane& plane = frame.planes[frame.plane_count++];
    plane.object_id = object.object_id;
    plane.com_m = to_vec3(object.com_m);
    if (!object.shaped()) {
      plane.point_m = to_vec3(object.point_m);
      plane.normal = to_vec3(object.normal);
      continue;
    }
    const BodyPose pose = impetus::test::pose_at(object.com_m);
    const BodyPose turned{object.com_m, Eigen::Quaterniond(object.axes)};
    const SurfacePoint surface =
        nearest_surface_point(object.shape, object.shape_traits().round ? pose : turned, finger_m);
    plane.point_m = to_vec3(surface.point_m);
    plane.normal = to_vec3(surface.normal);
    plane.shape = object.shape;
    plane.extent_m = plane_extent_m(object.shape);
    plane.body_axis_x = to_vec3(object.axes.col(0));
    plane.body_axis_y = to_vec3(object.axes.col(1));
  }
  return frame;
}

// The point finger's servo where the peg's tip would be on the hand's target (into the objects: the god-object
// holds its proxy on their surfaces).
void run_point(const Eigen::Vector3d& offset_m, int ticks) {
  const PlaneSet planes = impetus::test::clutter();
  HapticServo servo(ServoOptions{}, 1);
  std::vector<double> ns(static_cast<std::size_t>(ticks));
  int contact_ticks = 0;
  for (int tick = 0; tick < ticks; ++tick) {
    const GripPose grip = impetus::test::wander_target(tick, offset_m);
    FingerSample sample;
    sample.valid = true;
    sample.position_m = grip.position_m + grip.orientation * Eigen::Vector3d(0.0, 0.0, -0.05);  // the peg's tip
    const double now_s = tick * 1e-3;
    if (tick % kTicksPerWorldStep == 0) {
      servo.on_plane_frame(frame_for(planes, sample.position_m, static_cast<std::uint64_t>(tick / kTicksPerWorldStep)),
                           now_s);
    }
    const auto start = std::chrono::steady_clock::now();
    const TickResult& result = servo.tick(&sample, now_s, 1e-3);
    const auto stop = std::chrono::steady_clock::now();
    ns[static_cast<std::size_t>(tick)] = std::chrono::duration<double, std::nano>(stop - start).count();
    contact_ticks += result.active_planes > 0 ? 1 : 0;
  }
  std::sort(ns.begin(), ns.end());
  std::printf("point finger         16 objects  tick p50 %6.0f ns  p99 %6.0f ns  max %8.0f ns  (contact %4.1f%% of "
              "ticks; the servo's whole tick at the peg's tip on the hand's target)\n",
              ns[ns.size() / 2], ns[ns.size() * 99 / 100], ns.back(), 100.0 * contact_ticks / ticks);
}

// The peg striking a free cube off its centre against the world (tests/support/tool_strike.h): where the cube ends,
// and how far it turned, per world rate and coupling, against the 1 kHz world.
void run_strike() {
  const impetus::test::Strike reference = impetus::test::strike(1000.0, Coupling::impulse);
  std::printf("\npeg striking a 0.2 kg cube 15 mm off its centre (mu 0.3), against the 1 kHz world: x %.2f mm, "
              "yaw %.4f rad\n", 1e3 * reference.position_m.x(), reference.yaw_rad);
  std::printf("%8s %9s %12s %12s %14s\n", "coupling", "rate (Hz)", "x (mm)", "yaw (rad)", "yaw / 1 kHz's");
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    for (const double rate_hz : {1000.0, 100.0, 50.0, 20.0, 10.0}) {
      const impetus::test::Strike s = impetus::test::strike(rate_hz, coupling);
      std::printf("%8s %9.0f %12.2f %12.4f %14.3f\n", to_string(coupling), rate_hz, 1e3 * s.position_m.x(), s.yaw_rad,
                  s.yaw_rad / reference.yaw_rad);
    }
  }
}

// The hand levering a box up over a ledge's edge with the cube tool (tests/support/tool_strike.h): how far it tipped,
// at its highest and at the end of the hold, per world rate and coupling, against the 1 kHz world.
void run_lever() {
  const impetus::test::Lever reference = impetus::test::lever(1000.0, Coupling::impulse);
  std::printf("\nhand levering a 0.2 kg box up over a ledge's edge, against the 1 kHz world: peak %.4f rad, held %.4f "
              "rad\n", reference.peak_pitch_rad, reference.end_pitch_rad);
  std::printf("%8s %9s %11s %11s %14s %12s\n", "coupling", "rate (Hz)", "peak (rad)", "held (rad)", "held / 1 kHz's",
              "peak force");
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    for (const double rate_hz : {1000.0, 100.0, 50.0, 20.0}) {
      const impetus::test::Lever l = impetus::test::lever(rate_hz, coupling);
      std::printf("%8s %9.0f %11.4f %11.4f %14.3f %10.2f N\n", to_string(coupling), rate_hz, l.peak_pitch_rad,
                  l.end_pitch_rad, l.end_pitch_rad / reference.end_pitch_rad, l.peak_force_N);
    }
  }
}

void run_stability() {
  std::printf("\nclosed loop, cube pressed into a corner (hand 0.15 kg, 8 N·s/m, 6e-3 N·m·s/rad), 1.5 s:\n");
  std::printf("%9s %11s %8s %-8s %13s %16s\n", "k (N/m)", "k_r (N·m/rad)", "lag (ms)", "dampers", "E end / start",
              "largest rise (J)");
  for (const double k : {2000.0, 5000.0, 10000.0}) {
    for (const double k_r : {20.0, 100.0}) {
      for (const double lag_s : {0.0, 1e-3, 3e-3}) {
        for (const bool damped : {true, false}) {
          ToolCoupling coupling;
          coupling.stiffness_Npm = k;
          coupling.rotational_stiffness_Nmprad = k_r;
          coupling.damping_Nspm = damped ? k * 1e-3 : 0.0;
          coupling.rotational_damping_Nmsprad = damped ? k_r * 1e-3 : 0.0;
          coupling.max_force_N = 100.0;
          coupling.max_torque_Nm = 10.0;
          const std::vector<double> energy_J = impetus::test::corner_press_energy(coupling, lag_s, 1.5);
          double rise_J = 0.0;
          for (std::size_t q = 1; q < energy_J.size(); ++q) rise_J = std::max(rise_J, energy_J[q] - energy_J[q - 1]);
          std::printf("%9.0f %11.0f %8.0f %-8s %13.3f %16.2e\n", k, k_r, 1e3 * lag_s, damped ? "k·T" : "none",
                      energy_J.back() / energy_J.front(), rise_J);
        }
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  int ticks = 20000;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--help") == 0) {
      std::printf("usage: bench_tool_tick [--ticks N]\n"
                  "Times the tool's 6-DoF god-object beside the point finger's servo tick among 16 objects, then\n"
                  "prints the closed loop's energy over coupling stiffness, motor lag and dampers.\n");
      return 0;
    }
    if (std::strcmp(argv[k], "--ticks") == 0 && k + 1 < argc) {
      ticks = std::atoi(argv[++k]);
    } else {
      std::fprintf(stderr, "bench_tool_tick: unknown argument '%s' (--help)\n", argv[k]);
      return 2;
    }
  }
  if (ticks < 100) {
    std::fprintf(stderr, "bench_tool_tick: --ticks must be at least 100, not %d\n", ticks);
    return 2;
  }
  // The grip wanders 5 cm above the clutter's middle, so the tools' tips reach into it.
  const Eigen::Vector3d offset_m(0.0, 0.0, 0.05);
  run_tool("peg (box)", impetus::test::peg_tool(), offset_m, ticks);
  run_tool("probe (capsule)", impetus::test::probe_tool(), offset_m, ticks);
  run_point(offset_m, ticks);
  run_strike();
  run_lever();
  run_stability();
  return 0;
}
