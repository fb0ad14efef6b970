// SPDX-License-Identifier: Apache-2.0
// Spreading an impulse over substep slots (substep_spread.h): the weights are a distribution with the asked centroid,
// so momentum and a free body's displacement are those of the impulse at its centroid, and they are as spread as the
// centroid allows.

#include "world_manager/couplings/substep_spread.h"

#include <catch2/catch.hpp>

#include <vector>

namespace {

std::vector<double> weights(double centroid, int slot_count) {
  std::vector<double> w(static_cast<std::size_t>(slot_count), 0.0);
  impetus::spread_over_slots(centroid, slot_count, [&](int slot, double weight) {
    REQUIRE(slot >= 0);
    REQUIRE(slot < slot_count);
    w[static_cast<std::size_t>(slot)] += weight;
  });
  return w;
}

}  // namespace

TEST_CASE("substep spread: non-negative weights summing to one with the asked centroid, for every centroid") {
  for (int slot_count : {1, 2, 3, 10, 11, 101}) {
    for (int i = 0; i <= 400; ++i) {
      const double centroid = (slot_count - 1) * i / 400.0;
      const std::vector<double> w = weights(centroid, slot_count);
      double sum = 0.0;
      double moment = 0.0;
      for (std::size_t k = 0; k < w.size(); ++k) {
        CHECK(w[k] >= 0.0);
        sum += w[k];
        moment += static_cast<double>(k) * w[k];
      }
      INFO("slots " << slot_count << " centroid " << centroid);
      CHECK(sum == Approx(1.0).epsilon(1e-12));
      CHECK(moment == Approx(centroid).margin(1e-12));
    }
  }
}

TEST_CASE("substep spread: uniform at the middle, all in one slot at either end, spread wide in between") {
  const std::vector<double> middle = weights(5.0, 11);
  for (double w : middle) CHECK(w == Approx(1.0 / 11.0));
  CHECK(weights(0.0, 11)[0] == 1.0);
  CHECK(weights(10.0, 11)[10] == 1.0);
  // A centroid a third of the way in still uses every slot: no slot takes more than twice the uniform share.
  for (double w : weights(10.0 / 3.0, 11)) CHECK(w <= 2.0 / 11.0 + 1e-12);
  // Out of range is clamped to the ends.
  CHECK(weights(-3.0, 11)[0] == 1.0);
  CHECK(weights(99.0, 11)[10] == 1.0);
}
