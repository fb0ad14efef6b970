// SPDX-License-Identifier: Apache-2.0
// spidar_sim: a simulated SPIDAR and finger playing a scripted trajectory (DESIGN.md §1.2 step 1, §4). Parses the
// flags, attaches to a running haptic controller's device port and runs a DeviceNode until the trajectory ends; then
// detaches cleanly and exits 0.

#include "common/link/shm/shm_device_port.h"
#include "common/runtime/cli.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/trajectory.h"

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
  std::string device_spec = "spidar";
  HardwareParams hardware;
  FingerParams finger;
  CLI::App app{"spidar_sim: a simulated SPIDAR device and finger playing a scripted trajectory against a running "
               "haptic_controller."};
  app.add_option("--trajectory", trajectory_spec,
                 "CSV file with header t,x,y,z, or a built-in: tap|press|slide|circle[:key=value,...]")
      ->required();
  add_clock_flag(app, clock);
  add_output_flag(app, "--log", log_path, "CSV log: time, target, finger, velocity, force, tensions, counts");
  add_output_flag(app, "--summary", summary_path, "JSON summary written at exit (ticks, finger and device)");
  add_shm_flag(app, shm);
  app.add_option("--attach-timeout", attach_timeout_s, "seconds to wait for the haptic controller's port")
      ->check(positive_number(kMaxFlagSeconds));
  app.add_option("--device", device_spec,
                 "spidar (the built-in geometry) or spidar:FILE.json; must match the haptic controller's");
  app.add_option("--hand-stiffness", finger.hand_stiffness_Npm, "hand impedance stiffness, N/m (300)")
      ->check(positive_number(limits::kMaxStiffness_Npm));
  app.add_option("--hand-damping", finger.hand_damping_Nspm, "hand impedance damping, N·s/m (8)")
      ->check(number_in(0.0, limits::kMaxDamping_Nspm));
  app.add_option("--finger-mass", finger.mass_kg, "finger point mass, kg (0.1)")
      ->check(positive_number(kMaxFingerMass_kg));
  app.add_option("--motor-lag", hardware.motor_time_constant_s, "motor time constant, s (0 = ideal)")
      ->check(number_in(0.0, kMaxMotorLag_s));
  CLI11_PARSE(app, argc, argv);

  return run_node("spidar_sim", [&] {
    const Trajectory trajectory = load_trajectory(trajectory_spec);
    const SpidarDevice spidar = parse_device_spec(device_spec);
    DeviceSim sim(spidar.geometry, hardware, finger, trajectory);
    ShmDevicePortClient port(shm, clock, attach_timeout_s, {geometry_hash(spidar.geometry), spidar.source});
    DeviceNode node(sim, port, log_path, new_session_id());
    std::fprintf(stderr, "spidar_sim: attached to '%s' (%s), trajectory %.3f s\n", port.name().c_str(),
                 to_string(clock), trajectory.duration_s());
    const int status = node.run();
    write_summary(summary_path, node.summary());
    std::fprintf(stderr, "spidar_sim: detached after %llu ticks (%.3f s simulated)\n",
                 static_cast<unsigned long long>(node.ticks()), sim.time_s());
    return status;
  });
}
