// SPDX-License-Identifier: Apache-2.0
// spidar_sim: a simulated SPIDAR and finger playing a scripted trajectory (docs/architecture.md §1.2 step 1, §4), or
// the 8-string grip SPIDAR and the hand holding its grip playing a trajectory of poses (--device grip; docs/tool.md).
// Parses the flags, attaches to a running haptic controller's device port and runs a device node until the
// trajectory ends; then detaches cleanly and exits 0.

#include "common/link/shm/shm_device_port.h"
#include "common/runtime/cli.h"
#include "spidar_sim/simulated_fingers.h"
#include "spidar_sim/simulated_grip.h"

#include <memory>
#include <string>
#include <vector>

namespace {
// A finger with hand and forearm behind it is ~2 kg: 10 kg is beyond any body part a device is strapped to.
constexpr double kMaxFingerMass_kg = 10.0;
// Real capstan motors follow a current command within milliseconds; a 1 s lag is a device that cannot render.
constexpr double kMaxMotorLag_s = 1.0;
}  // namespace

int main(int argc, char** argv) {
  using namespace impetus;
  std::string trajectory_spec;
  ClockMode clock = ClockMode::realtime;
  std::string log_path;
  std::string summary_path;
  std::string shm = "impetus";
  double attach_timeout_s = 10.0;
  double world_wait_s = DeviceNode::kWorldWait_s;
  std::string device_spec = "spidar";
  HardwareParams hardware;
  FingerParams finger;
  CLI::App app{"spidar_sim: a simulated SPIDAR device and finger playing a scripted trajectory against a running "
               "haptic_controller."};
  std::vector<std::string> finger_specs;
  auto* trajectory_flag =
      app.add_option("--trajectory", trajectory_spec,
                     "CSV file with header t,x,y,z, or a built-in: tap|press|slide|circle[:key=value,...]");
  auto* finger_flag = app.add_option(
      "--finger", finger_specs,
      "NAME=TRAJECTORY, once per finger of a several-finger device (the haptic controller's --fingers): finger k "
      "attaches to its port k and plays its trajectory; all fingers run until the longest trajectory ends");
  trajectory_flag->excludes(finger_flag);
  finger_flag->excludes(trajectory_flag);
  add_clock_flag(app, clock);
  add_output_flag(app, "--log", log_path, "CSV log: time, target, finger, velocity, force, tensions, counts");
  add_output_flag(app, "--summary", summary_path, "JSON summary written at exit (ticks, finger and device)");
  add_shm_flag(app, shm);
  app.add_option("--attach-timeout", attach_timeout_s, "seconds to wait for the haptic controller's port")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--world-wait", world_wait_s,
                 "real time: seconds the trajectory holds at its start until the haptic controller renders a world "
                 "(10; 0 plays at once)")
      ->check(number_in(0.0, kMaxFlagSeconds));
  app.add_option("--device", device_spec,
                 "spidar (the built-in geometry) or spidar:FILE.json, or the 8-string grip SPIDAR holding a tool: "
                 "grip or grip:FILE.json (its trajectory may turn: t,x,y,z,qw,qx,qy,qz); must match the haptic "
                 "controller's");
  app.add_option("--hand-stiffness", finger.hand_stiffness_Npm, "hand impedance stiffness, N/m (300)")
      ->check(positive_number(limits::kMaxStiffness_Npm));
  app.add_option("--hand-damping", finger.hand_damping_Nspm, "hand impedance damping, N·s/m (8)")
      ->check(number_in(0.0, limits::kMaxDamping_Nspm));
  app.add_option("--finger-mass", finger.mass_kg, "finger point mass, kg (0.1)")
      ->check(positive_number(kMaxFingerMass_kg));
  app.add_option("--motor-lag", hardware.motor_time_constant_s, "motor time constant, s (0 = ideal)")
      ->check(number_in(0.0, kMaxMotorLag_s));
  if (const std::optional<int> status = parse_flags(app, "spidar_sim", argc, argv)) return *status;

  if (trajectory_spec.empty() && finger_specs.empty()) {
    std::fprintf(stderr, "spidar_sim: error: give --trajectory, or --finger NAME=TRAJECTORY for each finger\n");
    return 2;
  }

  return run_node("spidar_sim", [&] {
    if (names_grip(device_spec)) {
      for (const char* flag : {"--finger", "--finger-mass", "--motor-lag"}) {
        if (app.count(flag) > 0) throw std::invalid_argument(std::string(flag) + " is not for --device grip");
      }
      return run_simulated_grip({device_spec, trajectory_spec, shm, clock, attach_timeout_s, world_wait_s, log_path,
                                 summary_path, finger});
    }
    const SpidarDevice spidar = parse_device_spec(device_spec);
    std::vector<std::unique_ptr<ShmDevicePortClient>> ports;  // declared first: they outlive the nodes that hold them
    SimulatedFingers rig(load_fingers(trajectory_spec, finger_specs), spidar.geometry, hardware, finger);
    for (std::size_t k = 0; k < rig.size(); ++k) {
      ports.push_back(std::make_unique<ShmDevicePortClient>(
          shm, clock, attach_timeout_s, DeviceDescription{geometry_hash(spidar.geometry), spidar.source},
          static_cast<unsigned>(k)));
      rig.attach(k, *ports.back(), log_path, new_session_id()).set_world_wait(world_wait_s);
      std::fprintf(stderr, "spidar_sim: '%s' attached to '%s' (%s), trajectory %.3f s\n", rig.finger(k).name.c_str(),
                   ports.back()->name().c_str(), to_string(clock), rig.finger(k).trajectory.duration_s());
    }
    const int status = rig.run();
    write_summary(summary_path, rig.summary());
    std::fprintf(stderr, "spidar_sim: detached after %llu ticks (%.3f s simulated)\n",
                 static_cast<unsigned long long>(rig.node(0).ticks()), rig.node(0).sim().time_s());
    return status;
  });
}
