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

SpatialGrid::CellRange SpatialGrid::cells_of(const Eigen::AlignedBox3d& box) const {
  CellRange range;
  for (int a = 0; a < 3; ++a) {
    range.low[a] = cell_coordinate(box.min()[a], cell_size_m_);
    range.high[a] = cell_coordinate(box.max()[a], cell_size_m_);
  }
  return range;
}

void SpatialGrid::rebuild(const std::vector<Eigen::AlignedBox3d>& bounds) {
  entries_.clear();
  oversized_.clear();
  object_count_ = static_cast<std::int32_t>(bounds.size());
  for (std::int32_t id = 0; id < object_count_; ++id) {
    const Eigen::AlignedBox3d& box = bounds[static_cast<std::size_t>(id)];
    if (!box.min().allFinite() || !box.max().allFinite()) {
      oversized_.push_back(id);
      continue;
    }
    const CellRange range = cells_of(box);
    if (range.count() > kMaxCellsPerObject) {
      oversized_.push_back(id);
      continue;
    }
    for (int x = range.low.x(); x <= range.high.x(); ++x) {
      for (int y = range.low.y(); y <= range.high.y(); ++y) {
        for (int z = range.low.z(); z <= range.high.z(); ++z) entries_.emplace_back(key(x, y, z), id);
      }
    }
  }
  std::sort(entries_.begin(), entries_.end());
}

void SpatialGrid::query(const Eigen::AlignedBox3d& query, std::vector<std::int32_t>& out) const {
  out.clear();
  const auto return_all = [&] {
    for (std::int32_t id = 0; id < object_count_; ++id) out.push_back(id);
  };
  if (!query.min().allFinite() || !query.max().allFinite()) return return_all();
  const CellRange range = cells_of(query);
  if (range.count() > kMaxCellsPerQuery) return return_all();
  out = oversized_;
  for (int x = range.low.x(); x <= range.high.x(); ++x) {
    for (int y = range.low.y(); y <= range.high.y(); ++y) {
      for (int z = range.low.z(); z <= range.high.z(); ++z) {
        const CellKey cell = key(x, y, z);
        auto it = std::lower_bound(entries_.begin(), entries_.end(), std::pair<CellKey, std::int32_t>{cell, -1});
        for (; it != entries_.end() && it->first == cell; ++it) out.push_back(it->second);
      }
    }
  }
  // An object spanning several queried cells is listed once per cell.
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace impetus
