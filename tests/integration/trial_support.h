// SPDX-License-Identifier: Apache-2.0
#pragma once
// Integration tests launch the real daemons through scripts/run.sh (the same script users run) or directly, and read
// what they wrote. Trials run in lockstep unless a test is about real time.

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

namespace impetus::test {

// SpidarGeometry::max_force_N (10 N) plus rounding: the clamp rescales the force vector to 10 N, and the norm of the
// rescaled vector can come out an ulp or two above it.
inline constexpr double kDeviceMaxForce_N = 10.0 * (1.0 + 1e-12);

inline std::filesystem::path out_dir(const std::string& name) {
  const auto dir = std::filesystem::path(IMPETUS_BINARY_DIR) / "test-out" / (name + "-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string binary(const std::string& name) {
  return std::string(IMPETUS_BINARY_DIR) + "/" + name + "/" + name;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline nlohmann::json read_json(const std::filesystem::path& path) { return nlohmann::json::parse(read_text(path)); }

// How far the impulse the world applied to object `id` for endpoint 0 is from what that endpoint rendered on it: the
// largest |rendered − applied| / (1 + |rendered|) over the three axes (0 when the ledger is exact).
inline double ledger_gap(const nlohmann::json& summary, const std::string& id) {
  const nlohmann::json& rendered = summary["haptic"]["endpoints"][0]["impulse_by_object_Ns"][id];
  const nlohmann::json& applied = summary["world"]["endpoints"][0]["impulse_by_object_Ns"][id];
  double gap = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double r = rendered[axis].get<double>();
    gap = std::max(gap, std::abs(r - applied[axis].get<double>()) / (1.0 + std::abs(r)));
  }
  return gap;
}

// Runs a shell command; returns its exit status (or -1 if it did not exit normally).
inline int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Trial {
  int exit_status = -1;
  std::filesystem::path dir;
  nlohmann::json summary;
};

// scripts/run.sh with the given arguments (scene paths relative to the source tree), output in a fresh directory.
inline Trial run_trial(const std::string& name, const std::string& arguments) {
  Trial trial;
  trial.dir = out_dir(name);
  const std::string command = "cd '" + std::string(IMPETUS_SOURCE_DIR) + "' && IMPETUS_BUILD_DIR='" +
                              IMPETUS_BINARY_DIR + "' bash scripts/run.sh " + arguments + " --out '" +
                              trial.dir.string() + "' --quiet > '" + (trial.dir / "run.out").string() + "' 2>&1";
  trial.exit_status = shell(command);
  if (trial.exit_status == 0) trial.summary = read_json(trial.dir / "summary.json");
  return trial;
}


// Starts a daemon in the background with its output in `log`; returns its pid.
inline pid_t spawn(const std::vector<std::string>& argv, const std::filesystem::path& log) {
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
inline int wait_for(pid_t pid, double timeout_s) {
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


}  // namespace impetus::test
