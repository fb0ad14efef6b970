// SPDX-License-Identifier: Apache-2.0
// Tick cost of the haptic servo with its SPIDAR driver (kinematics + interpolation + proxy + force + accumulation +
// tensions) against the number of planes in the world frame: p50 / p99 in ns. Then the cost of one controller tick
// with 1, 2, 4 and 8 endpoints (a SPIDAR string set, port and servo per finger, 4 planes each, the pushes exchanged
// among them). The plane sweep runs without and with the passivity layer (the hand port's books and damper on every
// tick, the world handing energy back each frame). Prints only; no assertions. `--planes N` runs only the plane
// sweep's N, without the layer (for counting instructions). Last, the 8-string grip SPIDAR's device work a tick: its
// pose from eight lengths (warm, from the last tick's) and its tension distribution, within the motors and beyond.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <memory>
#include <vector>

#include "common/link/inproc/inproc_device_port.h"
#include "haptic_controller/device/finger_set.h"
#include "haptic_controller/device/grip_kinematics.h"
#include "haptic_controller/device/grip_tension.h"
#include "haptic_controller/device/spidar_driver.h"
#include "haptic_controller/servo.h"

using namespace impetus;

namespace {

constexpr int kTicks = 20000;
constexpr int kTicksPerWorldStep = 50;  // 1 kHz servo, 20 Hz world

// Planes around the workspace centre facing it, at 2–6 cm, a few of them moving and with friction, so the finger
// wandering near the centre touches several at once.
PlaneFrame make_frame(int planes, std::uint64_t index, double phase, bool port_layer = false) {
  PlaneFrame frame;
  // With the layer on, the world hands back a little energy every frame (its running total grows).
  frame.port_layer = port_layer ? 1u : 0u;
  frame.port_returned_J = port_layer ? 1e-3 * static_cast<double>(index) : 0.0;
  frame.frame_index = index;
  frame.world_session = 1;
  frame.world_period_s = kTicksPerWorldStep * 1e-3;
  frame.stiffness_Npm = 2000.0;
  const SpidarGeometry geometry;
  for (int k = 0; k < planes; ++k) {
    const double a = 2.399963 * k;  // golden-angle spiral over the sphere
    const double z = 1.0 - 2.0 * (k + 0.5) / planes;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d inward(-r * std::cos(a), -r * std::sin(a), -z);
    const double distance_m = 0.02 + 0.04 * ((k * 7) % 11) / 10.0 + 0.002 * std::sin(phase + k);
    Plane& plane = frame.planes[frame.plane_count++];
    plane.object_id = k;
    plane.flags = k % 2 ? kPlaneDynamic : 0u;
    plane.normal = to_vec3(inward);
    plane.point_m = to_vec3(to_eigen(geometry.centre_m) - distance_m * inward);
    plane.com_m = to_vec3(to_eigen(plane.point_m) - 0.025 * inward);
    plane.velocity_mps = {0.01, 0.0, 0.0};
    plane.static_friction = 0.5;
    plane.dynamic_friction = 0.3;
  }
  return frame;
}

// A device whose finger is `finger_m`, reported through its encoders (computed outside the timed section).
class ScriptedDevice final : public DeviceStepper {
 public:
  explicit ScriptedDevice(InProcessDevicePort& port) : port_(port) {}
  bool step_device() override {
    port_.publish_state(state);
    return true;
  }
  DeviceState state{};

 private:
  InProcessDevicePort& port_;
};

void run(int planes, bool port_layer) {
  ServoOptions options;
  HapticServo servo(options, 1);
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  InProcessDevicePort port(1e-3);
  ScriptedDevice device(port);
  port.connect(device);
  SpidarDriver driver(geometry, port, ClockMode::lockstep, 1);
  std::vector<double> ns(kTicks);
  int contact_ticks = 0;
  for (int tick = 0; tick < kTicks; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % kTicksPerWorldStep == 0)
      servo.on_plane_frame(make_frame(planes, tick / kTicksPerWorldStep, now_s, port_layer), now_s);
    const Eigen::Vector3d finger =
        to_eigen(geometry.centre_m) +
        0.05 * Eigen::Vector3d(std::sin(tick * 0.0031), std::sin(tick * 0.0023), std::sin(tick * 0.0017));
    impetus::set_first_strings(kinematics.encoder_counts(finger), device.state.encoder_counts);
    const auto start = std::chrono::steady_clock::now();
    const FingerSample* sample = driver.read(static_cast<std::uint64_t>(tick), now_s);
    const TickResult& result = servo.tick(sample, now_s, 1e-3);
    driver.command(static_cast<std::uint64_t>(tick), to_eigen(result.force_N), result.render);
    const auto stop = std::chrono::steady_clock::now();
    ns[tick] = std::chrono::duration<double, std::nano>(stop - start).count();
    contact_ticks += result.active_planes > 0 ? 1 : 0;
  }
  std::sort(ns.begin(), ns.end());
  std::printf("planes %3d  layer %-3s  tick p50 %8.0f ns  p99 %8.0f ns  max %8.0f ns  (contact ticks %.0f%%)\n",
              planes, port_layer ? "on" : "off", ns[kTicks / 2], ns[kTicks * 99 / 100], ns.back(),
              100.0 * contact_ticks / kTicks);
}

// One controller tick with `endpoints` fingers: the finger set's read (each finger's port turn and kinematics), a
// servo tick per finger, the push exchange, and the forces to every finger's strings.
void run_endpoints(int endpoints) {
  constexpr int kPlanes = 4;
  const SpidarGeometry geometry;
  const SpidarKinematics kinematics(geometry);
  std::vector<std::unique_ptr<InProcessDevicePort>> ports;
  std::vector<std::unique_ptr<ScriptedDevice>> devices;
  std::vector<std::unique_ptr<SpidarDriver>> drivers;
  std::vector<std::unique_ptr<HapticServo>> servos;
  std::vector<HapticDevice*> fingers;
  std::vector<HapticServo*> servo_list;
  for (int k = 0; k < endpoints; ++k) {
    ports.push_back(std::make_unique<InProcessDevicePort>(1e-3));
    devices.push_back(std::make_unique<ScriptedDevice>(*ports.back()));
    ports.back()->connect(*devices.back());
    drivers.push_back(std::make_unique<SpidarDriver>(geometry, *ports.back(), ClockMode::lockstep, 1));
    fingers.push_back(drivers.back().get());
    servos.push_back(std::make_unique<HapticServo>(ServoOptions{}, 1, static_cast<EndpointId>(k)));
    servo_list.push_back(servos.back().get());
  }
  FingerSet set(fingers);
  std::array<FingerCommand, kMaxFingers> commands{};
  std::vector<double> ns(kTicks);
  for (int tick = 0; tick < kTicks; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % kTicksPerWorldStep == 0) {
      for (auto& servo : servos) servo->on_plane_frame(make_frame(kPlanes, tick / kTicksPerWorldStep, now_s), now_s);
    }
    for (int k = 0; k < endpoints; ++k) {
      const Eigen::Vector3d finger =
          to_eigen(geometry.centre_m) + 0.05 * Eigen::Vector3d(std::sin(tick * 0.0031 + k), std::sin(tick * 0.0023),
                                                               std::sin(tick * 0.0017 - k));
      impetus::set_first_strings(kinematics.encoder_counts(finger), devices[k]->state.encoder_counts);
    }
    const auto start = std::chrono::steady_clock::now();
    const FingerSample* samples = set.read(static_cast<std::uint64_t>(tick), now_s);
    for (int k = 0; k < endpoints; ++k) {
      const TickResult& result = servos[k]->tick(&samples[k], now_s, 1e-3);
      commands[k].force_N = to_eigen(result.force_N);
      commands[k].render = result.render;
    }
    exchange_pushes(servo_list);
    set.command_fingers(static_cast<std::uint64_t>(tick), commands.data());
    const auto stop = std::chrono::steady_clock::now();
    ns[tick] = std::chrono::duration<double, std::nano>(stop - start).count();
  }
  std::sort(ns.begin(), ns.end());
  std::printf("endpoints %d  controller tick p50 %8.0f ns  p99 %8.0f ns  max %8.0f ns  (p50 per endpoint %.0f ns)\n",
              endpoints, ns[kTicks / 2], ns[kTicks * 99 / 100], ns.back(), ns[kTicks / 2] / endpoints);
}

// The grip's device work a tick, on a wandering, turning grip: the pose from its quantised lengths (warm start), then
// the tensions for a wrench within the motors, and for one beyond them (the largest scale's search too).
void run_grip() {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  std::vector<double> pose_ns(kTicks);
  std::vector<double> tension_ns(kTicks);
  std::vector<double> saturated_ns(kTicks);
  GripPose found;
  found.position_m = Eigen::Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  int failures = 0;
  for (int tick = 0; tick < kTicks; ++tick) {
    GripPose truth;
    const Eigen::Vector3d wander(std::sin(tick * 0.0031), std::sin(tick * 0.0023), std::sin(tick * 0.0017));
    truth.position_m =
        Eigen::Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]) + 0.05 * wander;
    truth.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::sin(tick * 0.002),
                                                             Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
    const GripLengths lengths = kinematics.lengths_m(kinematics.encoder_counts(truth));
    auto start = std::chrono::steady_clock::now();
    failures += kinematics.pose(lengths, found, found).status == GripSolveStatus::ok ? 0 : 1;
    auto stop = std::chrono::steady_clock::now();
    pose_ns[tick] = std::chrono::duration<double, std::nano>(stop - start).count();
    const GripWrenchMatrix w = kinematics.wrench_matrix(found);
    GripWrench wrench;
    wrench << 4.0 * std::sin(tick * 0.01), 3.0, -2.0, 0.02, -0.01, 0.03 * std::cos(tick * 0.01);
    start = std::chrono::steady_clock::now();
    const GripTensionSolution within =
        distribute_grip_tension(wrench, w, geometry.tension_min_N, geometry.tension_max_N);
    stop = std::chrono::steady_clock::now();
    tension_ns[tick] = std::chrono::duration<double, std::nano>(stop - start).count();
    start = std::chrono::steady_clock::now();
    const GripTensionSolution beyond =
        distribute_grip_tension(50.0 * wrench, w, geometry.tension_min_N, geometry.tension_max_N);
    stop = std::chrono::steady_clock::now();
    saturated_ns[tick] = std::chrono::duration<double, std::nano>(stop - start).count();
    failures += within.saturated || !beyond.saturated ? 1 : 0;
  }
  for (auto* samples : {&pose_ns, &tension_ns, &saturated_ns}) std::sort(samples->begin(), samples->end());
  std::printf("grip pose (8 strings, warm)      p50 %8.0f ns  p99 %8.0f ns\n", pose_ns[kTicks / 2],
              pose_ns[kTicks * 99 / 100]);
  std::printf("grip tensions within the motors  p50 %8.0f ns  p99 %8.0f ns\n", tension_ns[kTicks / 2],
              tension_ns[kTicks * 99 / 100]);
  std::printf("grip tensions beyond (scaled)    p50 %8.0f ns  p99 %8.0f ns  (%d unexpected outcomes)\n",
              saturated_ns[kTicks / 2], saturated_ns[kTicks * 99 / 100], failures);
}

}  // namespace

int main(int argc, char** argv) {
  // --planes N: only the plane sweep's N (scripts/bench.sh counts its instructions under callgrind).
  if (argc == 3 && std::string(argv[1]) == "--planes") {
    const int planes = std::atoi(argv[2]);
    if (planes < 1 || planes > static_cast<int>(kMaxPlanes)) {
      std::fprintf(stderr, "bench_haptic_tick: --planes must be 1 to %u, not '%s'\n", kMaxPlanes, argv[2]);
      return 2;
    }
    run(planes, false);
    return 0;
  }
  if (argc != 1) {
    std::fprintf(stderr, "usage: bench_haptic_tick [--planes N]\n");
    return argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") ? 0 : 2;
  }
  for (const bool port_layer : {false, true}) {
    for (const int planes : {1, 4, 16, 64}) run(planes, port_layer);
  }
  for (const int endpoints : {1, 2, 4, 8}) run_endpoints(endpoints);
  run_grip();
  return 0;
}
