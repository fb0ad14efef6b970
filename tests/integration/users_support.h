// SPDX-License-Identifier: Apache-2.0
#pragma once
// Two users on one lockstep world as separate processes (tests/integration/users_test.cpp, and the in-process loop's
// comparison with it): each user a haptic controller with its own device port and a simulated finger, A the master.

#include "common/link/shm/names.h"
#include "trial_support.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <string>
#include <vector>

namespace impetus::test {

// A finger that comes in along x from `from_x` to `to_x` over 0.5 s and holds there until 4 s.
inline std::filesystem::path side_press(const std::filesystem::path& dir, const std::string& name, double from_x,
                                        double to_x) {
  const std::filesystem::path path = dir / (name + ".csv");
  std::ofstream out(path);
  out << "t,x,y,z\n0," << from_x << ",0,0.025\n0.5," << to_x << ",0,0.025\n4," << to_x << ",0,0.025\n";
  return path;
}

// The x the finger of user A (from −x) and B (from +x) aims at, `depth_m` past its side of the tap scene's cube.
inline double user_a_target_x(double depth_m) { return 0.005 + depth_m; }
inline double user_b_target_x(double depth_m) { return 0.055 - depth_m; }

// Users A and B press the tap scene's cube (sides at x = 0.005 and 0.055 m) from −x and +x, `depth_a_m` and
// `depth_b_m` past their sides, in lockstep. Returns the run's directory.
inline std::filesystem::path two_users(const std::string& name, double depth_a_m, double depth_b_m) {
  const std::filesystem::path dir = out_dir(name);
  const std::string world_shm = "impetus_test_" + name + "_" + std::to_string(getpid());
  const std::string scene = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  const pid_t world = spawn({binary("world_manager"), "--scene", scene, "--clock", "lockstep", "--shm",
                                   world_shm, "--log", (dir / "world.csv").string(), "--summary",
                                   (dir / "world.json").string()},
                                  dir / "world.out");
  struct User {
    std::string name;
    double from_x, to_x;
    pid_t haptic = 0, device = 0;
  };
  User users[] = {{"a", -0.01, user_a_target_x(depth_a_m)}, {"b", 0.07, user_b_target_x(depth_b_m)}};
  for (User& user : users) {
    const std::string shm = world_shm + "_" + user.name;
    std::vector<std::string> argv = {binary("haptic_controller"), "--clock", "lockstep", "--shm", shm,
                                     "--world-shm", world_shm, "--log",
                                     (dir / ("haptic_" + user.name + ".csv")).string(), "--summary",
                                     (dir / ("haptic_" + user.name + ".json")).string()};
    if (user.name == "a") argv.insert(argv.end(), {"--followers", "1"});  // A leads, and starts when B is there
    user.haptic = spawn(argv, dir / ("haptic_" + user.name + ".out"));
    user.device = spawn({binary("spidar_sim"), "--clock", "lockstep", "--shm", shm, "--trajectory",
                               side_press(dir, user.name, user.from_x, user.to_x).string()},
                              dir / ("device_" + user.name + ".out"));
    if (user.name == "a") {
      // B starts once A holds the world's lockstep and waits for it (A says so), so A is the master in every run.
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (read_text(dir / "haptic_a.out").find("waiting for 1 more controller") == std::string::npos &&
             std::chrono::steady_clock::now() < give_up) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
  }
  for (User& user : users) CHECK(wait_for(user.device, 60.0) == 0);
  // As a user ends a lockstep run: the follower first, then the master, then the world.
  for (User* user : {&users[1], &users[0]}) {
    kill(user->haptic, SIGTERM);
    CHECK(wait_for(user->haptic, 10.0) == 0);
  }
  kill(world, SIGTERM);
  CHECK(wait_for(world, 10.0) == 0);
  INFO(read_text(dir / "haptic_a.out") << read_text(dir / "haptic_b.out"));
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + world_link_name(world_shm)));
  return dir;
}

}  // namespace impetus::test
