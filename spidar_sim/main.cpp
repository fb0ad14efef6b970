// SPDX-License-Identifier: Apache-2.0
// spidar_sim: a simulated SPIDAR and finger playing a scripted trajectory (docs/architecture.md §1.2 step 1, §4), or
// the 8-string grip SPIDAR and the hand holding its grip playing a trajectory of poses (--device grip; docs/tool.md).
// Parses the flags and runs the process they describe (app.h): it attaches to a running haptic controller's device
// port and runs a device node until the trajectory ends; then detaches cleanly and exits 0.

#include "common/runtime/cli.h"
#include "spidar_sim/app.h"

#include <optional>
#include <string>

namespace {
// A finger with hand and forearm behind it is ~2 kg: 10 kg is beyond any body part a device is strapped to.
constexpr double kMaxFingerMass_kg = 10.0;
// Real capstan motors follow a current command within milliseconds; a 1 s lag is a device that cannot render.
constexpr double kMaxMotorLag_s = 1.0;
}  // namespace

int main(int argc, char** argv) {
  using namespace impetus;
  SpidarSimFlags flags;
  CLI::App app{"spidar_sim: a simulated SPIDAR device and finger playing a scripted trajectory against a running "
               "haptic_controller."};
  auto* trajectory_flag =
      app.add_option("--trajectory", flags.trajectory_spec,
                     "CSV file with header t,x,y,z, or a built-in: tap|press|slide|circle[:key=value,...]");
  auto* finger_flag = app.add_option(
      "--finger", flags.finger_specs,
      "NAME=TRAJECTORY, once per finger of a several-finger device (the haptic controller's --fingers): finger k "
      "attaches to its port k and plays its trajectory; all fingers run until the longest trajectory ends");
  trajectory_flag->excludes(finger_flag);
  finger_flag->excludes(trajectory_flag);
  add_clock_flag(app, flags.clock);
  add_output_flag(app, "--log", flags.log_path, "CSV log: time, target, finger, velocity, force, tensions, counts");
  add_output_flag(app, "--summary", flags.summary_path, "JSON summary written at exit (ticks, finger and device)");
  add_shm_flag(app, flags.shm);
  app.add_option("--attach-timeout", flags.attach_timeout_s, "seconds to wait for the haptic controller's port")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--world-wait", flags.world_wait_s,
                 "real time: seconds the trajectory holds at its start until the haptic controller renders a world "
                 "(10; 0 plays at once)")
      ->check(number_in(0.0, kMaxFlagSeconds));
  app.add_option("--device", flags.device_spec,
                 "spidar (the built-in geometry) or spidar:FILE.json, or the 8-string grip SPIDAR holding a tool: "
                 "grip or grip:FILE.json (its trajectory may turn: t,x,y,z,qw,qx,qy,qz); must match the haptic "
                 "controller's");
  app.add_option("--hand-stiffness", flags.finger.hand_stiffness_Npm, "hand impedance stiffness, N/m (300)")
      ->check(positive_number(limits::kMaxStiffness_Npm));
  app.add_option("--hand-damping", flags.finger.hand_damping_Nspm, "hand impedance damping, N·s/m (8)")
      ->check(number_in(0.0, limits::kMaxDamping_Nspm));
  app.add_option("--finger-mass", flags.finger.mass_kg, "finger point mass, kg (0.1)")
      ->check(positive_number(kMaxFingerMass_kg));
  app.add_option("--motor-lag", flags.hardware.motor_time_constant_s, "motor time constant, s (0 = ideal)")
      ->check(number_in(0.0, kMaxMotorLag_s));
  if (const std::optional<int> status = parse_flags(app, "spidar_sim", argc, argv)) return *status;

  if (flags.trajectory_spec.empty() && flags.finger_specs.empty()) {
    std::fprintf(stderr, "spidar_sim: error: give --trajectory, or --finger NAME=TRAJECTORY for each finger\n");
    return 2;
  }

  for (const char* flag : {"--finger", "--finger-mass", "--motor-lag"}) {
    if (app.count(flag) > 0) flags.finger_flags_given.emplace_back(flag);
  }
  return run_node("spidar_sim", [&] { return run_spidar_sim(flags); });
}
