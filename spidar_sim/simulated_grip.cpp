// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/simulated_grip.h"

#include "common/link/shm/shm_device_port.h"
#include "common/runtime/cli.h"
#include "common/runtime/process.h"
#include "common/spidar/grip_geometry.h"
#include "spidar_sim/device_node.h"
#include "spidar_sim/grip_device_sim.h"

#include <cstdio>

namespace impetus {

int run_simulated_grip(const SimulatedGripOptions& options) {
  const GripDevice grip = parse_grip_spec(options.device_spec);
  GripHandParams hand;
  hand.stiffness_Npm = options.hand.hand_stiffness_Npm;
  hand.damping_Nspm = options.hand.hand_damping_Nspm;
  GripDeviceSim sim(grip.geometry, hand, load_trajectory(options.trajectory));
  ShmDevicePortClient port(options.shm, options.clock, options.attach_timeout_s,
                           DeviceDescription{grip_geometry_hash(grip.geometry), grip.source}, 0);
  GripDeviceNode node(sim, port, options.log_path, new_session_id());
  node.set_world_wait(options.world_wait_s);
  std::fprintf(stderr, "spidar_sim: the grip attached to '%s' (%s)\n", port.name().c_str(), to_string(options.clock));
  const int status = node.run();
  write_summary(options.summary_path, node.summary());
  std::fprintf(stderr, "spidar_sim: detached after %llu ticks (%.3f s simulated)\n",
               static_cast<unsigned long long>(node.ticks()), sim.time_s());
  return status;
}

}  // namespace impetus
