// SPDX-License-Identifier: Apache-2.0
// The shared-memory world link's endpoint slots: haptic controllers take the next free slots as they attach, each
// endpoint's reports and frames travel in its own slot, a controller that needs more slots than are free is refused
// with the numbers, and slots given back are taken again.

#include "common/link/shm/shm_world_link.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace impetus {
namespace {

// A 20 Hz world's link on `clock`.
WorldLinkInfo world_info(ClockMode clock) {
  WorldLinkInfo info;
  info.world_rate_hz = 20.0;
  info.world_period_s = 0.05;
  info.clock = clock;
  return info;
}

}  // namespace

TEST_CASE("shm world link: controllers take endpoint slots in turn, and each endpoint's frames and reports stay in "
          "its own slot") {
  const std::string shm = test::unique_segment_name("slots");
  ShmWorldLinkServer server(shm, world_info(ClockMode::realtime));
  auto one = std::make_unique<ShmWorldLinkClient>(shm, ClockMode::realtime, 1.0, 1);
  ShmWorldLinkClient two(shm, ClockMode::realtime, 1.0, 2);
  CHECK(one->slot_of(0) == 0);
  CHECK(two.slot_of(0) == 1);
  CHECK(two.slot_of(1) == 2);

  // A report of the second controller's endpoint 1 arrives in slot 2, and only there.
  HapticReport report;
  report.haptic_session = 77;
  report.endpoint = 1;
  report.tick = 5;
  two.publish_report(report);
  HapticReport received;
  REQUIRE(server.latest_report(2, received));
  CHECK(received.haptic_session == 77);
  CHECK(received.endpoint == 1);
  CHECK_FALSE(server.latest_report(0, received));
  CHECK_FALSE(server.latest_report(1, received));

  // A frame for slot 1 reaches the second controller's endpoint 0, and nobody else.
  PlaneFrame frame;
  frame.world_session = 3;
  frame.world_period_s = 0.05;
  frame.frame_index = 9;
  server.publish_frame(1, frame);
  PlaneFrame out;
  CHECK_FALSE(one->receive_frame(0, out));
  CHECK_FALSE(two.receive_frame(1, out));
  REQUIRE(two.receive_frame(0, out));
  CHECK(out.frame_index == 9);

  // Five slots are left: a controller of six fingers is refused, naming the numbers.
  CHECK_THROWS_WITH(ShmWorldLinkClient(shm, ClockMode::realtime, 1.0, 6),
                    Catch::Contains("5 free endpoint slot(s) of 8") && Catch::Contains("needs 6"));
  // A controller that leaves gives its slot back; the next one takes it.
  one.reset();
  ShmWorldLinkClient three(shm, ClockMode::realtime, 1.0, 1);
  CHECK(three.slot_of(0) == 0);
}

TEST_CASE("shm world link: on a lockstep world the first controller is the master and the next ones follow its "
          "ticks") {
  const std::string shm = test::unique_segment_name("master");
  ShmWorldLinkServer server(shm, world_info(ClockMode::lockstep));
  ShmWorldLinkClient master(shm, ClockMode::lockstep, 1.0, 1);
  ShmWorldLinkClient follower(shm, ClockMode::lockstep, 1.0, 2);
  CHECK_FALSE(master.follower());
  CHECK(follower.follower());
  CHECK(follower.slot_of(0) == 1);

  // The master hands ticks 0..9 to the follower; each returns only once the follower has finished that tick.
  std::vector<std::uint64_t> followed;
  std::thread follower_loop([&] {
    for (;;) {
      std::uint64_t tick = 0;
      if (follower.wait_follower_turn(tick) != TurnResult::ok) break;
      followed.push_back(tick);
      follower.finish_follower_turn();
    }
  });
  for (std::uint64_t tick = 0; tick < 10; ++tick) master.lead_followers(tick);
  master.end_session();  // the follower's next wait ends with `shutdown`
  follower_loop.join();
  CHECK(followed == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
}

}  // namespace impetus
