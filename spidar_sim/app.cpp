// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/app.h"

#include "common/link/shm/shm_device_port.h"
#include "common/runtime/cli.h"
#include "spidar_sim/simulated_fingers.h"
#include "spidar_sim/simulated_grip.h"

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus {

int run_spidar_sim(const SpidarSimFlags& flags) {
  if (names_grip(flags.device_spec)) {
    if (!flags.finger_flags_given.empty()) {
      throw std::invalid_argument(flags.finger_flags_given.front() + " is not for --device grip");
    }
    return run_simulated_grip({flags.device_spec, flags.trajectory_spec, flags.shm, flags.clock,
                               flags.attach_timeout_s, flags.world_wait_s, flags.log_path, flags.summary_path,
                               flags.finger});
  }
  const SpidarDevice spidar = parse_device_spec(flags.device_spec);
  std::vector<std::unique_ptr<ShmDevicePortClient>> ports;  // declared first: they outlive the nodes that hold them
  SimulatedFingers rig(load_fingers(flags.trajectory_spec, flags.finger_specs), spidar.geometry, flags.hardware,
                       flags.finger);
  for (std::size_t k = 0; k < rig.size(); ++k) {
    ports.push_back(std::make_unique<ShmDevicePortClient>(
        flags.shm, flags.clock, flags.attach_timeout_s,
        DeviceDescription{geometry_hash(spidar.geometry), spidar.source}, static_cast<unsigned>(k)));
    rig.attach(k, *ports.back(), flags.log_path, new_session_id()).set_world_wait(flags.world_wait_s);
    std::fprintf(stderr, "spidar_sim: '%s' attached to '%s' (%s), trajectory %.3f s\n", rig.finger(k).name.c_str(),
                 ports.back()->name().c_str(), to_string(flags.clock), rig.finger(k).trajectory.duration_s());
  }
  const int status = rig.run();
  write_summary(flags.summary_path, rig.summary());
  std::fprintf(stderr, "spidar_sim: detached after %llu ticks (%.3f s simulated)\n",
               static_cast<unsigned long long>(rig.node(0).ticks()), rig.node(0).sim().time_s());
  return status;
}

}  // namespace impetus
