// SPDX-License-Identifier: Apache-2.0
// The device's command watchdog (spidar_sim/command_watchdog.h): a stalled servo's last command stops being applied
// kCommandStale_s after it came, and a new command is applied at once.
#include "spidar_sim/command_watchdog.h"

#include <catch2/catch.hpp>

using impetus::CommandWatchdog;
using impetus::DeviceCommand;
using impetus::kCommandStale_s;

TEST_CASE("command watchdog: a command stops being applied once no new one has come for the stale time") {
  CommandWatchdog watchdog;
  CHECK_FALSE(watchdog.applies(nullptr, 0.0));  // none yet: minimum output
  DeviceCommand command;
  command.tick = 7;
  command.haptic_session = 1;
  // The servo runs at 1 kHz: every device tick sees a new command.
  for (int tick = 0; tick < 100; ++tick) {
    command.tick = 7 + static_cast<std::uint64_t>(tick);
    REQUIRE(watchdog.applies(&command, tick * 1e-3));
  }
  // The servo stalls after tick 99 (t = 0.099 s): its last command holds for the stale time, then no longer.
  const double last_s = 0.099;
  CHECK(watchdog.applies(&command, last_s + 0.5 * kCommandStale_s));
  CHECK(watchdog.applies(&command, last_s + kCommandStale_s - 1e-6));
  CHECK_FALSE(watchdog.applies(&command, last_s + kCommandStale_s + 1e-3));
  CHECK_FALSE(watchdog.applies(&command, last_s + 2.0));
  CHECK(watchdog.stale_ticks() == 2);
  // It resumes: the first new command is applied at once.
  ++command.tick;
  CHECK(watchdog.applies(&command, last_s + 2.001));
  // A restarted servo (a new session) may start its ticks again: a new session's command is new.
  command.tick = 1;
  command.haptic_session = 2;
  CHECK(watchdog.applies(&command, last_s + 2.2));
}
