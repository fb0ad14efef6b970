#pragma once
// The command-line vocabulary every node's main.cpp shares (DESIGN.md §4): the same flag names, checks and wording
// everywhere, and bad values rejected with the flag, the value and the reason.

#include "common/contract/frames.h"
#include "common/runtime/lockstep.h"
#include "common/runtime/process.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <exception>
#include <map>
#include <string>

namespace impetus {

// CLI11 maps for the enum flags, so a bad value is rejected with the flag, the value and the choices.
inline const std::map<std::string, ClockMode> kClockNames{{"realtime", ClockMode::realtime},
                                                          {"lockstep", ClockMode::lockstep}};
inline const std::map<std::string, Coupling> kCouplingNames{
    {"impulse", Coupling::impulse}, {"position", Coupling::position}, {"local", Coupling::local}};

// A CLI11 validator for file paths we will write: not empty, the directory must exist and be writable.
std::string check_writable_path(const std::string& path);

// A CLI11 validator for numeric flags: the value must be a finite number (CLI11's range checks let NaN through).
CLI::Validator finite_number();

void add_clock_flag(CLI::App& app, ClockMode& clock);
void add_shm_flag(CLI::App& app, std::string& shm);
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
