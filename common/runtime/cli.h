// SPDX-License-Identifier: Apache-2.0
#pragma once
// The command-line vocabulary every node's main.cpp shares (docs/architecture.md §4): the same flag names, checks and
// wording everywhere, and bad values rejected with the flag, the value and the reason.

#include "common/contract/frames.h"
#include "common/contract/limits.h"
#include "common/link/link_options.h"
#include "common/runtime/ascii.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/message_text.h"
#include "common/runtime/process.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <exception>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace impetus {

// CLI11 maps for the enum flags, so a bad value is rejected with the flag, the value and the choices.
inline const std::map<std::string, ClockMode> kClockNames{{"realtime", ClockMode::realtime},
                                                          {"lockstep", ClockMode::lockstep}};
inline const std::map<std::string, Coupling> kCouplingNames{
    {"impulse", Coupling::impulse}, {"position", Coupling::position}, {"local", Coupling::local}};
inline const std::map<std::string, bool> kOnOffNames{{"on", true}, {"off", false}};

// A CLI11 transform for an enum flag: its name (any case) becomes the enum's value; another text is refused with
// "must be a, b or c, not 'x'" (CLI11's own CheckedTransformer prints its mapping table).
template <class T>
CLI::Validator enum_names(const std::map<std::string, T>& names) {
  return CLI::Validator(
      [&names](std::string& value) {
        if (const auto found = names.find(ascii_lower(value)); found != names.end()) {
          value = std::to_string(static_cast<long long>(found->second));
          return std::string();
        }
        std::vector<std::string> choices;
        for (const auto& [name, unused] : names) choices.push_back(name);
        return "must be " + one_of(choices) + ", not '" + value + "'";
      },
      "");
}

// A CLI11 validator for file paths we will write: not empty, the directory must exist and be writable.
std::string check_writable_path(const std::string& path);

// CLI11 validators for numeric flags. Each parses the text itself, so NaN, infinities, integers too large for their
// type and values out of range are all rejected with the flag and a readable reason ("must be between 0.1 and 10000,
// not 1e+300"). CLI11's own range checks let NaN through and print their bounds with 309 digits.
CLI::Validator number_in(double lowest, double highest);  // lowest <= x <= highest
CLI::Validator positive_number(double highest);            // 0 < x <= highest
CLI::Validator whole_number_in(std::uint64_t lowest, std::uint64_t highest);

// Longest --duration, --world-wait or --attach-timeout: 10^7 s (116 days) is longer than any session, and tick counts
// at 20 kHz stay exact far beyond it, so the bound only rejects typing mistakes and values that would overflow.
inline constexpr double kMaxFlagSeconds = 1e7;

// Adds --version ("NAME VERSION") and --check-flags, and parses argv. Returns the exit status main must return at once,
// or nothing to go on: 0 after --help, --version or --check-flags, which print and do nothing else; 2 for bad usage (an unknown flag, a bad or missing
// value), after a message naming it. Bad input found later (a file that cannot be used) is run_node's: status 1.
std::optional<int> parse_flags(CLI::App& app, const char* name, int argc, char** argv);
// The project's version ("0.2.0").
const char* impetus_version();

void add_clock_flag(CLI::App& app, ClockMode& clock);
void add_shm_flag(CLI::App& app, std::string& shm);
// --link shm|dds, --dds-domain, --dds-partition.
void add_link_flags(CLI::App& app, LinkOptions& link);
inline const std::map<std::string, LinkKind> kLinkNames{{"shm", LinkKind::shm}, {"dds", LinkKind::dds}};
void add_output_flag(CLI::App& app, const std::string& flag, std::string& path, const std::string& description);

// Writes a node's half of summary.json to `path` (nothing if it is empty); throws std::runtime_error naming the path
// if it cannot be written.
void write_summary(const std::string& path, const nlohmann::json& summary);

// Runs a node's body after the flags were parsed: installs the stop handlers, and turns an exception into
// "NAME: error: WHAT" on stderr and exit status 1.
template <class Body>
int run_node(const char* name, Body&& body) {
  install_stop_handlers();
  try {
    return body();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s: error: %s\n", name, error.what());
    return 1;
  }
}

}  // namespace impetus
