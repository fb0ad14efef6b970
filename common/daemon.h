#pragma once
// What the three daemons share outside their loops: a stop flag raised by SIGINT/SIGTERM, opening a segment that
// its creator may not have created yet, and the command-line vocabulary of DESIGN.md §4.

#include "common/link_types.h"
#include "common/lockstep.h"
#include "common/segment.h"

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <map>
#include <string>
#include <thread>

namespace impetus {

// Raised by SIGINT or SIGTERM once install_stop_handlers() ran; loops poll it and finish their current step.
extern std::atomic<bool> g_stop_requested;
void install_stop_handlers();

// Opens `name`, retrying while it does not exist, is still being created, or is a stale segment whose creator died
// (its successor is about to take it over), for up to `timeout_s` or until a stop is requested. Errors other than
// "not there yet" (another layout version, another kind) are thrown at once.
template <class Layout>
Segment<Layout> open_when_ready(const std::string& name, double timeout_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    try {
      Segment<Layout> segment = Segment<Layout>::open(name);
      if (segment.creator_alive()) return segment;
      if (std::chrono::steady_clock::now() > give_up || g_stop_requested.load()) {
        throw SegmentError("segment '" + name + "' was left by process " +
                           std::to_string(segment->header.creator_pid) + ", which is no longer running");
      }
    } catch (const SegmentError& error) {
      const std::string message = error.what();
      const bool not_there_yet = message.find("is its creator running") != std::string::npos ||
                                 message.find("still being created") != std::string::npos ||
                                 message.find("too small for a header") != std::string::npos;
      if (!not_there_yet || std::chrono::steady_clock::now() > give_up || g_stop_requested.load()) throw;
    }
    // 2 ms: a trial's processes start together, and the polls are what a short lockstep trial waits on.
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// CLI11 maps for the enum flags, so a bad value is rejected with the flag, the value and the choices.
inline const std::map<std::string, ClockMode> kClockNames{{"realtime", ClockMode::realtime},
                                                          {"lockstep", ClockMode::lockstep}};
inline const std::map<std::string, Coupling> kCouplingNames{
    {"impulse", Coupling::impulse}, {"position", Coupling::position}, {"local", Coupling::local}};
const char* to_string(Coupling coupling);

// A CLI11 validator for file paths we will write: the directory must exist and be writable.
std::string check_writable_path(const std::string& path);

// The flags every daemon shares (DESIGN.md §4), with the same names, checks and wording everywhere.
void add_clock_flag(CLI::App& app, ClockMode& clock);
void add_shm_flag(CLI::App& app, std::string& shm);
void add_output_flag(CLI::App& app, const std::string& flag, std::string& path, const std::string& description);

}  // namespace impetus
