// SPDX-License-Identifier: Apache-2.0
#pragma once
// Opening a segment whose creator may not have created it yet (processes of a trial start together).

#include "common/link/shm/segment.h"
#include "common/runtime/process.h"

#include <chrono>
#include <string>
#include <thread>

namespace impetus {

// Opens `name`, retrying while it is missing, under construction, or a stale segment whose creator died (its
// successor is about to take it over), for up to `timeout_s` or until a stop is requested. Other problems (another
// layout version, another kind) are thrown at once.
template <class Layout>
Segment<Layout> open_when_ready(const std::string& name, double timeout_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    const bool last_try = std::chrono::steady_clock::now() > give_up || g_stop_requested.load();
    try {
      Segment<Layout> segment = Segment<Layout>::open(name);
      if (segment.creator_alive()) return segment;
      if (last_try) {
        throw SegmentError(SegmentProblem::missing, "segment '" + name + "' was left by process " +
                                                        std::to_string(segment->header.creator_pid) +
                                                        ", which is no longer running");
      }
    } catch (const SegmentError& error) {
      if (!error.transient() || last_try) throw;
    }
    // 2 ms: a trial's processes start together, and the polls are what a short lockstep trial waits on.
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

}  // namespace impetus
