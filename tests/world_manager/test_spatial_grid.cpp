// SPDX-License-Identifier: Apache-2.0
// The spatial grid (spatial_grid.h) kept up to date object by object answers every query as a grid built afresh, and
// as brute force does.

#include "world_manager/features/spatial_grid.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

using Eigen::AlignedBox3d;
using Eigen::Vector3d;
using impetus::SpatialGrid;

namespace {

AlignedBox3d random_box(std::mt19937& random, double span_m) {
  std::uniform_real_distribution<double> where(-span_m, span_m);
  std::uniform_real_distribution<double> size(0.001, 0.12);  // up to a few 5 cm cells: some oversized for the grid
  const Vector3d low(where(random), where(random), where(random));
  return AlignedBox3d(low, low + Vector3d(size(random), size(random), size(random)));
}

std::vector<std::int32_t> brute_force(const std::vector<AlignedBox3d>& boxes, const std::vector<bool>& present,
                                      const AlignedBox3d& query) {
  std::vector<std::int32_t> out;
  for (std::size_t id = 0; id < boxes.size(); ++id) {
    if (present[id] && boxes[id].intersects(query)) out.push_back(static_cast<std::int32_t>(id));
  }
  return out;
}

// The ids of `candidates` whose box overlaps `query`: what a caller's exact test keeps.
std::vector<std::int32_t> overlapping(const std::vector<std::int32_t>& candidates,
                                      const std::vector<AlignedBox3d>& boxes, const AlignedBox3d& query) {
  std::vector<std::int32_t> out;
  for (const std::int32_t id : candidates) {
    if (boxes[static_cast<std::size_t>(id)].intersects(query)) out.push_back(id);
  }
  return out;
}

}  // namespace

TEST_CASE("spatial grid: moved, removed and re-added objects are found as by a fresh grid and by brute force") {
  std::mt19937 random(7);
  constexpr std::size_t kObjects = 400;
  std::vector<AlignedBox3d> boxes(kObjects);
  for (auto& box : boxes) box = random_box(random, 0.5);
  // One box that cannot be placed in cells at all.
  boxes[13] = AlignedBox3d(Vector3d::Constant(-std::numeric_limits<double>::infinity()), Vector3d::Zero());
  std::vector<bool> present(kObjects, true);
  SpatialGrid kept(0.05);
  kept.rebuild(boxes);

  std::uniform_int_distribution<std::size_t> pick(0, kObjects - 1);
  for (int round = 0; round < 200; ++round) {
    // Move, remove or re-add a few objects.
    for (int change = 0; change < 5; ++change) {
      const std::size_t id = pick(random);
      if (id == 13) continue;
      if (round % 7 == 0 && present[id]) {
        kept.remove(static_cast<std::int32_t>(id));
        present[id] = false;
        continue;
      }
      // Small moves mostly (cells often unchanged), now and then a jump across the scene.
      boxes[id] = change % 3 == 0 ? random_box(random, 0.5)
                                  : boxes[id].translated(Vector3d::Constant(0.004 * (change - 2)));
      kept.update(static_cast<std::int32_t>(id), boxes[id]);
      present[id] = true;
    }
    SpatialGrid fresh(0.05);
    fresh.reset(kObjects);
    for (std::size_t id = 0; id < kObjects; ++id) {
      if (present[id]) fresh.update(static_cast<std::int32_t>(id), boxes[id]);
    }
    const AlignedBox3d query = random_box(random, 0.5);
    std::vector<std::int32_t> from_kept;
    std::vector<std::int32_t> from_fresh;
    kept.query(query, from_kept);
    fresh.query(query, from_fresh);
    REQUIRE(from_kept == from_fresh);
    REQUIRE(std::is_sorted(from_kept.begin(), from_kept.end()));
    REQUIRE(overlapping(from_kept, boxes, query) == brute_force(boxes, present, query));
    // The unplaceable box is returned by every query while present.
    REQUIRE(std::binary_search(from_kept.begin(), from_kept.end(), 13));
  }
}
