// SPDX-License-Identifier: Apache-2.0
#pragma once
// A uniform grid over object bounding boxes, so the feature query (paper §3.1 step 1) and the broadphase of sleeping
// bodies look only at the cells around a point: a query's cost grows with what is near it, not with the size of the
// world.
//
// The grid is kept up to date object by object: moving one object costs the cells it leaves and enters, so a world
// in which a few objects move pays for those few (rebuild() is the O(N) start). Objects too large for the grid
// (spanning more than kMaxCellsPerObject cells) and objects with non-finite boxes are kept in a short list that every
// query returns.

#include <Eigen/Geometry>

#include <cstdint>
#include <unordered_map>
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

  // Starts afresh with ids 0..bounds.size()-1, each at its box.
  void rebuild(const std::vector<Eigen::AlignedBox3d>& bounds);
  // Starts afresh with room for ids 0..object_count-1 and none of them in the grid.
  void reset(std::size_t object_count);
  // Puts `id` at `box` (inserting it if absent); costs only when its cells change.
  void update(std::int32_t id, const Eigen::AlignedBox3d& box);
  // Takes `id` out of the grid (nothing if absent).
  void remove(std::int32_t id);

  // Every id in the grid whose box may overlap `query` (a superset: the caller makes the exact test), each once, in
  // ascending order. `out` is cleared first.
  void query(const Eigen::AlignedBox3d& query, std::vector<std::int32_t>& out) const;

  double cell_size_m() const { return cell_size_m_; }

 private:
  using CellKey = std::uint64_t;
  struct CellRange {
    Eigen::Array3i low = Eigen::Array3i::Zero();
    Eigen::Array3i high = Eigen::Array3i::Constant(-1);
    std::int64_t count() const;
    bool operator==(const CellRange& other) const { return (low == other.low).all() && (high == other.high).all(); }
  };
  // Where an object is: absent, in the cells of `range`, or in the oversized list.
  enum class Placement : std::uint8_t { absent, cells, oversized };
  struct Entry {
    Placement placement = Placement::absent;
    CellRange range;
  };

  CellRange cells_of(const Eigen::AlignedBox3d& box) const;
  static CellKey key(int x, int y, int z);
  template <typename Visit>
  static void for_each_cell(const CellRange& range, Visit&& visit);

  double cell_size_m_;
  std::vector<Entry> entries_;  // per id
  std::unordered_map<CellKey, std::vector<std::int32_t>> cells_;
  std::vector<std::int32_t> oversized_;
};

}  // namespace impetus
