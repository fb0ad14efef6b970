// SPDX-License-Identifier: Apache-2.0
#include "trial_support.h"

#include <catch2/catch.hpp>

#include <signal.h>

#include <filesystem>
#include <fstream>

namespace impetus {

TEST_CASE("spidar_sim attaches, detaches and re-attaches to a running lockstep haptic controller") {
  const auto dir = test::out_dir("attach");
  const std::string shm = "impetus_test_attach_" + std::to_string(getpid());
  // A 0.2 s trajectory in free space, far from the cube.
  const auto trajectory = dir / "short.csv";
  std::ofstream(trajectory) << "t,x,y,z\n0,-0.05,0,0.1\n0.2,-0.06,0,0.1\n";

  const std::string scene = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  const pid_t world = test::spawn({test::binary("world_manager"), "--scene", scene, "--clock", "lockstep", "--shm", shm},
                            dir / "world.out");
  const pid_t haptic = test::spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm, "--summary",
                              (dir / "haptic.json").string()},
                             dir / "haptic.out");
  for (int session = 0; session < 2; ++session) {
    INFO("device session " << session);
    const pid_t device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm, "--trajectory",
                                trajectory.string()},
                               dir / ("device" + std::to_string(session) + ".out"));
    CHECK(test::wait_for(device, 30.0) == 0);
    INFO(test::read_text(dir / ("device" + std::to_string(session) + ".out")));
    CHECK_THAT(test::read_text(dir / ("device" + std::to_string(session) + ".out")), Catch::Contains("detached"));
  }
  kill(haptic, SIGTERM);
  CHECK(test::wait_for(haptic, 10.0) == 0);
  CHECK(test::wait_for(world, 10.0) == 0);
  INFO(test::read_text(dir / "haptic.out"));

  const auto summary = test::read_json(dir / "haptic.json")["haptic"];
  // Each session is 200 device ticks plus the one turn on which the device says it is leaving; lockstep time does
  // not advance while no device is attached, so exactly two ticks ran without a device.
  CHECK(summary["no_device_ticks"] == 2);
  CHECK(summary["ticks"].get<int>() >= 2 * 200);
  CHECK(summary["faults"] == 0);
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".world"));
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".device"));
}

}  // namespace impetus
