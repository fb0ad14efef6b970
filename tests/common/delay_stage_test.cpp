// SPDX-License-Identifier: Apache-2.0
// The delay and loss stage a real-time link puts on what it receives (common/link/delay_stage.h).
#include "common/link/delay_stage.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>

using impetus::DelayStage;
using impetus::LinkLoss;

TEST_CASE("a delay stage hands the newest value over once it is due, never before, each once") {
  constexpr std::int64_t kDelay_ns = 20'000'000;  // 20 ms
  DelayStage<int> stage;
  stage.reset(kDelay_ns, 8, LinkLoss{}, 0);
  CHECK(stage.active());
  CHECK(stage.next_due_ns() == std::numeric_limits<std::int64_t>::max());
  stage.push(1'000'000, 1);   // due at 21 ms
  stage.push(5'000'000, 2);   // due at 25 ms
  stage.push(30'000'000, 3);  // due at 50 ms
  CHECK(stage.next_due_ns() == 21'000'000);
  CHECK(stage.take_due(20'999'999) == nullptr);
  const int* due = stage.take_due(26'000'000);  // 1 and 2 are due: the newest, 2
  REQUIRE(due != nullptr);
  CHECK(*due == 2);
  CHECK(stage.take_due(26'000'000) == nullptr);  // handed over once
  CHECK(stage.next_due_ns() == 50'000'000);
  due = stage.take_due(50'000'000);
  REQUIRE(due != nullptr);
  CHECK(*due == 3);
  CHECK(stage.dropped() == 0);
  CHECK(stage.lost() == 0);
}

TEST_CASE("a full delay stage drops its oldest value and counts it, and a lossy one loses what its stream says") {
  DelayStage<int> full;
  full.reset(1'000, 2, LinkLoss{}, 0);
  full.push(0, 1);
  full.push(0, 2);
  full.push(0, 3);  // 1 goes
  CHECK(full.dropped() == 1);
  const int* due = full.take_due(1'000);
  REQUIRE(due != nullptr);
  CHECK(*due == 3);

  DelayStage<int> lossy;
  lossy.reset(0, 16, LinkLoss{0.5, 1.0, 3}, 0);
  CHECK(lossy.active());  // no delay, but loss
  impetus::LossProcess same_stream(LinkLoss{0.5, 1.0, 3}, 0);
  int arrived = 0;
  for (int k = 0; k < 1000; ++k) {
    lossy.push(k, k);
    const bool lost = same_stream.lose();
    const int* value = lossy.take_due(k);
    CHECK((value == nullptr) == lost);  // a value with no delay is due at once, unless the stream lost it
    arrived += value != nullptr ? 1 : 0;
  }
  CHECK(lossy.lost() == static_cast<std::uint64_t>(1000 - arrived));
  CHECK(arrived > 400);
  CHECK(arrived < 600);

  DelayStage<int> off;
  off.reset(0, 1, LinkLoss{}, 0);
  CHECK_FALSE(off.active());
}
