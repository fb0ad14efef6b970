// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/cli.h"

#include "common/link/shm/names.h"
#include "common/runtime/message_text.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
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

namespace {

// Parses a decimal number; "" on success, otherwise why not.
std::string parse_number(const std::string& input, double& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtod(input.c_str(), &end);
  if (input.empty() || end == input.c_str() || *end != '\0') return "'" + excerpt(input, 40) + "' is not a number";
  // strtod saturates an overflow to ±HUGE_VAL (infinite) and flushes an underflow towards 0: the first is an error,
  // the second an honest reading of the number.
  if (!std::isfinite(value)) return "must be a finite number, not '" + excerpt(input, 40) + "'";
  return "";
}

}  // namespace

CLI::Validator number_in(double lowest, double highest) {
  return CLI::Validator(
      [lowest, highest](std::string& input) -> std::string {
        double value = 0.0;
        if (std::string problem = parse_number(input, value); !problem.empty()) return problem;
        if (value < lowest || value > highest) {
          return "must be between " + readable(lowest) + " and " + readable(highest) + ", not " + excerpt(input, 40);
        }
        return "";
      },
      "NUMBER in [" + readable(lowest) + ", " + readable(highest) + "]");
}

CLI::Validator positive_number(double highest) {
  return CLI::Validator(
      [highest](std::string& input) -> std::string {
        double value = 0.0;
        if (std::string problem = parse_number(input, value); !problem.empty()) return problem;
        if (!(value > 0.0)) return "must be positive, not " + excerpt(input, 40);
        if (value > highest) return "must be at most " + readable(highest) + ", not " + excerpt(input, 40);
        return "";
      },
      "POSITIVE <= " + readable(highest));
}

CLI::Validator whole_number_in(std::uint64_t lowest, std::uint64_t highest) {
  return CLI::Validator(
      [lowest, highest](std::string& input) -> std::string {
        const auto outside = [&] {
          return "must be a whole number from " + std::to_string(lowest) + " to " + std::to_string(highest) +
                 ", not " + excerpt(input, 40);
        };
        if (input.empty() || input.find_first_not_of("0123456789") != std::string::npos) return outside();
        // More digits than the bound has cannot be in range, and must not reach strtoull (which saturates).
        if (input.find_first_not_of('0') != std::string::npos &&
            input.size() - input.find_first_not_of('0') > std::to_string(highest).size()) {
          return outside();
        }
        errno = 0;
        const unsigned long long value = std::strtoull(input.c_str(), nullptr, 10);
        if (errno == ERANGE || value < lowest || value > highest) return outside();
        return "";
      },
      "INT in [" + std::to_string(lowest) + ", " + std::to_string(highest) + "]");
}

void add_clock_flag(CLI::App& app, ClockMode& clock) {
  app.add_option("--clock", clock, "realtime or lockstep (all three processes must agree)")
      ->transform(enum_names(kClockNames));
}

const char* impetus_version() { return IMPETUS_VERSION; }

std::optional<int> parse_flags(CLI::App& app, const char* name, int argc, char** argv) {
  app.set_version_flag("--version", std::string(name) + " " + impetus_version());
  bool check_only = false;
  app.add_flag("--check-flags", check_only, "check the flags and exit (0: good, 2: bad usage with a message); starts "
               "nothing (scripts/run.sh checks every process's flags before it starts any)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    // --help, --version and a flag that printed what was asked and ended the parse (CLI::Success) are code 0; any
    // other is bad usage. app.exit prints the help, the version or the message naming the flag.
    return app.exit(error) == 0 ? 0 : 2;
  }
  if (check_only) return 0;
  return std::nullopt;
}

void add_shm_flag(CLI::App& app, std::string& shm) {
  app.add_option("--shm", shm, "shared-memory name of the link (default impetus)")
      ->check([](const std::string& name) { return shm_name_problem(name); });
}

void add_link_flags(CLI::App& app, LinkOptions& link) {
  app.add_option("--link", link.kind,
                 "transport of the world link: shm (shared memory on this host, the default) or dds (DDS, world and "
                 "controller on the same or different hosts; real time only)")
      ->transform(enum_names(kLinkNames));
  app.add_option("--dds-domain", link.dds.domain_id, "--link dds: the DDS domain id, 0 to 232 (0)")
      ->check(whole_number_in(0, kMaxDdsDomainId));
  app.add_option("--dds-partition", link.dds.partition,
                 "--link dds: the DDS partition; worlds in other partitions of the domain are invisible (impetus)")
      ->check([](const std::string& name) { return name.empty() ? std::string("must not be empty") : std::string(); });
  app.add_option("--dds-security", link.dds.security_dir,
                 "--link dds: a secured link (DDS Security: only participants certified by the same CA, each allowed "
                 "only its own topics, everything encrypted): this participant's folder made by "
                 "scripts/dds_security.sh")
      ->check(CLI::ExistingDirectory);
  app.add_option_function<double>(
         "--dds-delay-ms", [&link](double ms) { link.dds.delay_s = ms * 1e-3; },
         "--link dds: hold what this process receives back by MS milliseconds (a network delay for experiments; give "
         "both ends the same; 0)")
      ->check(number_in(0.0, kMaxDdsDelay_s * 1e3));
  app.add_option("--dds-loss", link.dds.loss.rate,
                 "--link dds: lose this fraction of what this process receives, 0 to 0.5 (for experiments; 0)")
      ->check(number_in(0.0, 0.5));
  app.add_option("--dds-loss-burst", link.dds.loss.burst_packets,
                 "--link dds: the mean run of lost packets, 1 to 1000 (1: independent losses)")
      ->check(number_in(1.0, 1000.0));
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
