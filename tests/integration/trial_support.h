#pragma once
// Integration tests launch the real daemons through scripts/run.sh (the same script users run) or directly, and read
// what they wrote. Trials run in lockstep unless a test is about real time.

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace impetus::test {

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

}  // namespace impetus::test
