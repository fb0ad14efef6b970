// SPDX-License-Identifier: Apache-2.0
// The device tick runs in a 1 kHz loop: it must not touch the heap (counted by tests/support/allocation_counter.h;
// not in sanitizer builds, which own operator new).
#include "spidar_sim/device_sim.h"
#include "tests/support/allocation_counter.h"

#include <catch2/catch.hpp>

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("tick does not allocate") {
  using namespace impetus;
  constexpr double kTick_s = 1e-3;
  DeviceSim sim(SpidarGeometry{}, HardwareParams{1e-3}, FingerParams{}, load_trajectory("circle"));
  sim.tick({0.0, 0.0, 0.0, 0.0}, kTick_s);
  test::start_counting_allocations();
  for (int k = 0; k < 1000; ++k) sim.tick({1.0, 2.0, 3.0, 4.0}, kTick_s);
  CHECK(test::stop_counting_allocations() == 0);
  // The counter works: an allocation is seen.
  test::start_counting_allocations();
  // A call of operator new, not a new-expression: the compiler may elide an unused new-expression.
  void* probe = ::operator new(sizeof(int));
  CHECK(test::stop_counting_allocations() == 1);
  ::operator delete(probe);
}
#endif
