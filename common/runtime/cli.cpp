#include "common/runtime/cli.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace impetus {

std::string check_writable_path(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return "the path is empty";
  const fs::path parent = fs::absolute(fs::path(path)).parent_path();
  std::error_code error;
  if (!fs::is_directory(parent, error)) return "directory '" + parent.string() + "' does not exist";
  if (access(parent.c_str(), W_OK) != 0) return "directory '" + parent.string() + "' is not writable";
  if (fs::is_directory(fs::path(path), error)) return "'" + path + "' is a directory";
  return "";
}

CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(input.c_str(), &end);
        if (input.empty() || end == input.c_str() || *end != '\0') return "'" + input + "' is not a number";
        if (!std::isfinite(value)) return "must be a finite number, not '" + input + "'";
        return "";
      },
      "FINITE");
}

void add_clock_flag(CLI::App& app, ClockMode& clock) {
  app.add_option("--clock", clock, "realtime or lockstep (all three processes must agree)")
      ->transform(CLI::CheckedTransformer(kClockNames, CLI::ignore_case));
}

void add_shm_flag(CLI::App& app, std::string& shm) {
  app.add_option("--shm", shm, "shared-memory name of the link (default impetus)");
}

void add_output_flag(CLI::App& app, const std::string& flag, std::string& path, const std::string& description) {
  app.add_option(flag, path, description)->check(CLI::Validator(check_writable_path, "WRITABLE"));
}

void write_summary(const std::string& path, const nlohmann::json& summary) {
  if (path.empty()) return;
  std::ofstream out(path);
  out << summary.dump(2) << '\n';
  out.flush();  // a full disk shows on the flush, not on the buffered write
  if (!out) throw std::runtime_error("cannot write summary '" + path + "' (" + std::strerror(errno) + ")");
}

}  // namespace impetus
