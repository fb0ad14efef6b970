// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world log (docs/architecture.md §4 "Logs"): a CSV with a header row and one row per world step, time first, then
// for every dynamic object its pose, velocity and the impulse the world applied to it (this step and since the start),
// then the cumulative reaction into static geometry, and last the haptic clock's time of the report the step applied
// (World::last_report_haptic_time_s; NaN before any), which puts the world's rows on the finger's clock. Column names
// carry units: `cube.x_m`, `cube.jx_Ns`, `cube.jx_total_Ns`, `haptic_time_s`.
//
// Written out of the world's turn: a step only copies its numbers into a preallocated ring (common/runtime/rt_log.h),
// and the log's own thread formats and writes them, so in lockstep the haptic side does not wait on the world's CSV.
// A row has a column group per dynamic object, so it goes into the ring as fixed-size records (the time, one per
// object, the static reaction), which the writer joins back into the same row.

#include "common/runtime/rt_log.h"
#include "world_manager/world.h"

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace impetus {

struct WorldLogRecord {
  enum class Part : std::uint32_t { time, object, deformable, statics };
  static constexpr std::size_t kObjectColumns = 19;  // position 3, quaternion 4, velocity 3 + 3, impulse 3 + 3
  Part part = Part::time;
  // time: values[0]; deformable: dent, volume, push; statics: the first four
  std::array<double, kObjectColumns> values{};
};

class WorldLog {
 public:
  // Opens `path`, writes the header and starts the writer thread; throws std::runtime_error naming the path if the
  // file cannot be opened. Keeps a reference to `world`, which must outlive the log.
  WorldLog(const World& world, const std::string& path);

  // Queues the row of the state after the world's last step. Never drops a row: if the writer has fallen a whole
  // ring behind (a slow disk), waits for room, as the world did when it wrote rows itself.
  void record();
  // Writes what is queued, stops the writer and flushes the file. Idempotent.
  void close() { log_.close(); }
  // Whether a write failed (reported on stderr when it happened).
  bool failed() const { return log_.failed(); }
  // Formats one queued record on the calling thread (rt_log.h drain_one); for a lockstep world between its turns.
  bool drain_one() { return log_.drain_one(); }

  static std::string header(const Scene& scene);
  static void format(std::ostream& out, const WorldLogRecord& record);

 private:
  const World& world_;
  std::vector<WorldLogRecord> row_;  // one row's records, filled by record() (allocated once)
  RtLog<WorldLogRecord> log_;
};

}  // namespace impetus
