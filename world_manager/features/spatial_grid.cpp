// SPDX-License-Identifier: Apache-2.0
#include "world_manager/features/spatial_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace impetus {

namespace {

// Cell coordinates are packed into 21 bits each; clamping keeps far-away (or runaway) objects valid keys. With 1 cm
// cells this still spans ±10 km, far outside any scene.
constexpr int kCellCoordinateLimit = (1 << 20) - 1;

int cell_coordinate(double x_m, double cell_size_m) {
  const double cell = std::floor(x_m / cell_size_m);
  return static_cast<int>(std::clamp(cell, double{-kCellCoordinateLimit}, double{kCellCoordinateLimit}));
}

void erase_id(std::vector<std::int32_t>& ids, std::int32_t id) {
  const auto found = std::find(ids.begin(), ids.end(), id);
  if (found == ids.end()) return;
  *found = ids.back();  // order within a cell does not matter: queries sort
  ids.pop_back();
}

}  // namespace

SpatialGrid::SpatialGrid(double cell_size_m) : cell_size_m_(cell_size_m) {
  if (!(cell_size_m > 0.0) || !std::isfinite(cell_size_m)) {
    throw std::invalid_argument("SpatialGrid: cell size must be positive and finite");
  }
}

std::int64_t SpatialGrid::CellRange::count() const {
  const Eigen::Array3i span = high - low + 1;
  return std::int64_t{span.x()} * span.y() * span.z();
}

SpatialGrid::CellKey SpatialGrid::key(int x, int y, int z) {
  constexpr int kBits = 21;
  constexpr std::uint64_t kMask = (std::uint64_t{1} << kBits) - 1;
  const auto pack = [](int c) { return static_cast<std::uint64_t>(c + kCellCoordinateLimit) & kMask; };
  return (pack(x) << (2 * kBits)) | (pack(y) << kBits) | pack(z);
}

template <typename Visit>
void SpatialGrid::for_each_cell(const CellRange& range, Visit&& visit) {
  for (int x = range.low.x(); x <= range.high.x(); ++x) {
    for (int y = range.low.y(); y <= range.high.y(); ++y) {
      for (int z = range.low.z(); z <= range.high.z(); ++z) visit(key(x, y, z));
    }
  }
}

SpatialGrid::CellRange SpatialGrid::cells_of(const Eigen::AlignedBox3d& box) const {
  CellRange range;
  for (int a = 0; a < 3; ++a) {
    range.low[a] = cell_coordinate(box.min()[a], cell_size_m_);
    range.high[a] = cell_coordinate(box.max()[a], cell_size_m_);
  }
  return range;
}

void SpatialGrid::reset(std::size_t object_count) {
  entries_.assign(object_count, Entry{});
  cells_.clear();
  oversized_.clear();
}

void SpatialGrid::rebuild(const std::vector<Eigen::AlignedBox3d>& bounds) {
  reset(bounds.size());
  for (std::size_t id = 0; id < bounds.size(); ++id) update(static_cast<std::int32_t>(id), bounds[id]);
}

void SpatialGrid::remove(std::int32_t id) {
  if (id < 0 || static_cast<std::size_t>(id) >= entries_.size()) return;
  Entry& entry = entries_[static_cast<std::size_t>(id)];
  if (entry.placement == Placement::oversized) erase_id(oversized_, id);
  if (entry.placement == Placement::cells) {
    for_each_cell(entry.range, [&](CellKey cell) {
      const auto found = cells_.find(cell);
      if (found == cells_.end()) return;
      erase_id(found->second, id);
      if (found->second.empty()) cells_.erase(found);
    });
  }
  entry.placement = Placement::absent;
}

void SpatialGrid::update(std::int32_t id, const Eigen::AlignedBox3d& box) {
  if (id < 0) return;
  if (static_cast<std::size_t>(id) >= entries_.size()) entries_.resize(static_cast<std::size_t>(id) + 1);
  const bool finite = box.min().allFinite() && box.max().allFinite();
  const CellRange range = finite ? cells_of(box) : CellRange{};
  const Placement placement = finite && range.count() <= kMaxCellsPerObject ? Placement::cells : Placement::oversized;
  Entry& entry = entries_[static_cast<std::size_t>(id)];
  if (entry.placement == placement && (placement == Placement::oversized || entry.range == range)) return;
  remove(id);
  entry.placement = placement;
  entry.range = range;
  if (placement == Placement::oversized) {
    oversized_.push_back(id);
    return;
  }
  for_each_cell(range, [&](CellKey cell) { cells_[cell].push_back(id); });
}

void SpatialGrid::query(const Eigen::AlignedBox3d& query, std::vector<std::int32_t>& out) const {
  out.clear();
  const auto return_all = [&] {
    for (std::size_t id = 0; id < entries_.size(); ++id) {
      if (entries_[id].placement != Placement::absent) out.push_back(static_cast<std::int32_t>(id));
    }
  };
  if (!query.min().allFinite() || !query.max().allFinite()) return return_all();
  const CellRange range = cells_of(query);
  if (range.count() > kMaxCellsPerQuery) return return_all();
  out = oversized_;
  for_each_cell(range, [&](CellKey cell) {
    const auto found = cells_.find(cell);
    if (found != cells_.end()) out.insert(out.end(), found->second.begin(), found->second.end());
  });
  // An object spanning several queried cells is listed once per cell.
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace impetus
