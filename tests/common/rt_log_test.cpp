// SPDX-License-Identifier: Apache-2.0
// The log ring the real-time loops write through: rows arrive complete and in order, a lockstep producer waits rather
// than lose one, rows pushed together stay together, and what cannot fit is counted, not lost silently.
#include "common/runtime/rt_log.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <array>
#include <atomic>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace impetus {
namespace {

struct Row {
  int value = 0;
  int last_of_group = 1;  // 1: the row ends a line
};

std::string temp_path(const char* name) {
  return "/tmp/impetus_rt_log_test_" + std::to_string(getpid()) + "_" + name + ".csv";
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void format(std::ostream& out, const Row& row) { out << row.value << (row.last_of_group != 0 ? "\n" : ","); }

}  // namespace

TEST_CASE("a lockstep log keeps every row in order though its ring is far smaller than what is pushed") {
  const std::string path = temp_path("order");
  {
    RtLog<Row> log(path, "value", format, 4, LogOverflow::wait);
    for (int k = 0; k < 5000; ++k) log.push({k, 1});
    log.close();
    CHECK(log.dropped() == 0);
  }
  const auto lines = lines_of(path);
  REQUIRE(lines.size() == 5001);
  CHECK(lines[0] == "value");
  int out_of_order = 0;
  for (int k = 0; k < 5000; ++k) out_of_order += lines[static_cast<std::size_t>(k) + 1] == std::to_string(k) ? 0 : 1;
  CHECK(out_of_order == 0);
  std::remove(path.c_str());
}

TEST_CASE("rows pushed together arrive together and in order, across the ring's end and while the drain runs") {
  // Groups of 3 rows make one line "a,b,c"; a ring of 7 makes groups wrap around its end and the producer wait.
  const std::string path = temp_path("groups");
  constexpr int kGroups = 3000;
  {
    RtLog<Row> log(path, "a,b,c", format, 7, LogOverflow::wait);  // 7: groups straddle the ring's end
    for (int g = 0; g < kGroups; ++g) {
      const std::array<Row, 3> group{Row{3 * g, 0}, Row{3 * g + 1, 0}, Row{3 * g + 2, 1}};
      log.push_all(group);
    }
    log.close();
    CHECK(log.dropped() == 0);
  }
  const auto lines = lines_of(path);
  REQUIRE(lines.size() == kGroups + 1);
  int wrong = 0;
  for (int g = 0; g < kGroups; ++g) {
    const std::string expected = std::to_string(3 * g) + "," + std::to_string(3 * g + 1) + "," + std::to_string(3 * g + 2);
    wrong += lines[static_cast<std::size_t>(g) + 1] == expected ? 0 : 1;
  }
  CHECK(wrong == 0);
  std::remove(path.c_str());
}

TEST_CASE("rows formatted by the producer between pushes and by the drain thread arrive once each, in order") {
  // A lockstep process formats its own rows while it waits for its turn (drain_one) as the drain thread does every
  // 2 ms: whichever takes the file formats the next row.
  const std::string path = temp_path("shared_drain");
  constexpr int kRows = 20000;
  int formatted_by_producer = 0;
  {
    RtLog<Row> log(path, "value", format, 64, LogOverflow::wait);
    for (int k = 0; k < kRows; ++k) {
      log.push({k, 1});
      if (k % 3 == 0 && log.drain_one()) ++formatted_by_producer;
    }
    while (log.drain_one()) ++formatted_by_producer;
    log.close();
  }
  const auto lines = lines_of(path);
  REQUIRE(lines.size() == kRows + 1);
  int wrong = 0;
  for (int k = 0; k < kRows; ++k) wrong += lines[static_cast<std::size_t>(k) + 1] == std::to_string(k) ? 0 : 1;
  CHECK(wrong == 0);
  CHECK(formatted_by_producer > 0);  // the producer did take part
  std::remove(path.c_str());
}

TEST_CASE("a group larger than the ring is counted as dropped instead of waiting forever") {
  const std::string path = temp_path("too_big");
  RtLog<Row> log(path, "v", format, 2, LogOverflow::wait);
  const std::array<Row, 3> group{Row{1, 0}, Row{2, 0}, Row{3, 1}};
  log.push_all(group);
  log.close();
  CHECK(log.dropped() == 3);
  CHECK(lines_of(path).size() == 1);  // the header only
  std::remove(path.c_str());
}

}  // namespace impetus
