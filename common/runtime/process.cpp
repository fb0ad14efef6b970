// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/process.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <random>

namespace impetus {

std::atomic<bool> g_stop_requested{false};

namespace {
extern "C" void on_stop_signal(int) { g_stop_requested.store(true); }
}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // No SA_RESTART: a blocking sleep or wait returns EINTR and its loop re-checks the flag.
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

std::uint64_t new_session_id() {
  static std::atomic<std::uint64_t> calls{0};
  std::random_device entropy;
  const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  std::uint64_t session = (static_cast<std::uint64_t>(entropy()) << 32) ^ entropy() ^ now ^
                          (static_cast<std::uint64_t>(::getpid()) << 16) ^ (calls.fetch_add(1) * 0x9E3779B97F4A7C15ull);
  return session == 0 ? 1 : session;
}

bool process_alive(std::int32_t pid) { return pid > 0 && ::kill(pid, 0) == 0; }

}  // namespace impetus
