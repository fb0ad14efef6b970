// SPDX-License-Identifier: Apache-2.0
#pragma once
// A uniform grid over object bounding boxes, so the feature query (paper §3.1 step 1) looks only at the cells around
// the finger: its cost grows with what is near the finger, not with the size of the world.
//
// Rebuilt once per world step (O(N log N) in the number of objects, the same order as stepping them). Objects too large
// for the grid (spanning more than kMaxCellsPerObject cells) are kept in a short list that every query returns.

#include <Eigen/Geometry>

#include <cstdint>
#include <utility>
#include <vector>

namespace impetus {

class SpatialGrid {
 public:
  // A box spanning more cells than this is cheaper to test on every query than to register in all of them.
  static constexpr std::int64_t kMaxCellsPerObject = 64;
  // A query box larger than this many cells (a very fast finger) falls back to returning every object.
  static constexpr std::int64_t kMaxCellsPerQuery = 4096;

  // `cell_size_m` > 0: about the size of a typical object or the reach radius, whichever is larger.
  explicit SpatialGrid(double cell_size_m);

  // Rebuilds from scratch; ids are 0..bounds.size()-1. Non-finite boxes go to the always-returned list.
  void rebuild(const std::vector<Eigen::AlignedBox3d>& bounds);

  // Every id whose box may overlap `query` (a superset: the caller makes the exact test), each once, in ascending
  // order. `out` is cleared first.
  void query(const Eigen::AlignedBox3d& query, std::vector<std::int32_t>& out) const;

  double cell_size_m() const { return cell_size_m_; }

 private:
  using CellKey = std::uint64_t;
  struct CellRange {
    Eigen::Array3i low;
    Eigen::Array3i high;
    std::int64_t count() const;
  };
  CellRange cells_of(const Eigen::AlignedBox3d& box) const;
  static CellKey key(int x, int y, int z);

  double cell_size_m_;
  std::int32_t object_count_ = 0;
  std::vector<std::pair<CellKey, std::int32_t>> entries_;  // sorted by key, then id
  std::vector<std::int32_t> oversized_;
};

}  // namespace impetus
