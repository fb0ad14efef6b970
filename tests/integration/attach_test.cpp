#include "trial_support.h"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

namespace impetus {
namespace {

// Starts a daemon in the background with its output in `log`; returns its pid.
pid_t spawn(const std::vector<std::string>& argv, const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    std::vector<char*> args;
    for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  return pid;
}

// Waits up to `timeout_s` for a child; returns its exit status, or -1 (and kills it) if it did not exit in time.
int wait_for(pid_t pid, double timeout_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > give_up) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("spidar_sim attaches, detaches and re-attaches to a running lockstep haptic controller") {
  const auto dir = test::out_dir("attach");
  const std::string shm = "impetus_test_attach_" + std::to_string(getpid());
  // A 0.2 s trajectory in free space, far from the cube.
  const auto trajectory = dir / "short.csv";
  std::ofstream(trajectory) << "t,x,y,z\n0,-0.05,0,0.1\n0.2,-0.06,0,0.1\n";

  const std::string scene = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  const pid_t world = spawn({test::binary("world_manager"), "--scene", scene, "--clock", "lockstep", "--shm", shm},
                            dir / "world.out");
  const pid_t haptic = spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm, "--summary",
                              (dir / "haptic.json").string()},
                             dir / "haptic.out");
  for (int session = 0; session < 2; ++session) {
    INFO("device session " << session);
    const pid_t device = spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm, "--trajectory",
                                trajectory.string()},
                               dir / ("device" + std::to_string(session) + ".out"));
    CHECK(wait_for(device, 30.0) == 0);
    INFO(test::read_text(dir / ("device" + std::to_string(session) + ".out")));
    CHECK_THAT(test::read_text(dir / ("device" + std::to_string(session) + ".out")), Catch::Contains("detached"));
  }
  kill(haptic, SIGTERM);
  CHECK(wait_for(haptic, 10.0) == 0);
  CHECK(wait_for(world, 10.0) == 0);
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
