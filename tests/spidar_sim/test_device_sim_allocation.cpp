// SPDX-License-Identifier: Apache-2.0
// The device tick runs in a 1 kHz loop: it must not touch the heap. This file replaces the global operator new to
// count allocations; AddressSanitizer owns operator new itself, so under it the check is skipped.
#include "spidar_sim/device_sim.h"

#include <catch2/catch.hpp>

#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define IMPETUS_COUNT_ALLOCATIONS 1
#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#endif

TEST_CASE("tick does not allocate") {
#ifdef IMPETUS_COUNT_ALLOCATIONS
  using namespace impetus;
  constexpr double kTick_s = 1e-3;
  DeviceSim sim(SpidarGeometry{}, HardwareParams{1e-3}, FingerParams{}, load_trajectory("circle"));
  sim.tick({0.0, 0.0, 0.0, 0.0}, kTick_s);
  const long before = g_allocations.load();
  for (int k = 0; k < 1000; ++k) sim.tick({1.0, 2.0, 3.0, 4.0}, kTick_s);
  CHECK(g_allocations.load() == before);
  // The counter works: an allocation is seen.
  auto* probe = new int(1);
  CHECK(g_allocations.load() == before + 1);
  delete probe;
#else
  WARN("allocation counting is disabled under sanitizers");
#endif
}
