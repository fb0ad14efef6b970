// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/deformable_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace impetus {

namespace {

// Cells along an edge of `length_m` at most `cell_m` each (the grid fits the face exactly).
std::size_t cells_along(double length_m, double cell_m) {
  return static_cast<std::size_t>(std::max(1.0, std::ceil(length_m / cell_m - 1e-9)));
}

}  // namespace

std::size_t DeformableSurface::cells_for(const DeformableMaterial& material, const Eigen::Vector3d& half_size_m) {
  const double columns = std::ceil(2.0 * half_size_m.x() / material.cell_m);
  const double rows = std::ceil(2.0 * half_size_m.y() / material.cell_m);
  const double cells = columns * rows;
  return cells > static_cast<double>(kMaxCells) ? kMaxCells + 1 : static_cast<std::size_t>(cells);
}

double DeformableSurface::cell_steps_per_second(const DeformableMaterial& material,
                                                const Eigen::Vector3d& half_size_m) {
  const double columns = static_cast<double>(cells_along(2.0 * half_size_m.x(), material.cell_m));
  const double rows = static_cast<double>(cells_along(2.0 * half_size_m.y(), material.cell_m));
  const double cell_x_m = 2.0 * half_size_m.x() / columns;
  const double cell_y_m = 2.0 * half_size_m.y() / rows;
  return columns * rows * ElasticMembrane::kSubstepsPerRadian * material.highest_frequency_radps(cell_x_m, cell_y_m);
}

DeformableSurface::DeformableSurface(const DeformableMaterial& material, const Eigen::Vector3d& half_size_m,
                                     const Eigen::Vector3d& position_m, const Eigen::Quaterniond& orientation)
    : material_(material), half_size_m_(half_size_m), position_m_(position_m), orientation_(orientation.normalized()) {
  if (cells_for(material, half_size_m) > kMaxCells) {
    throw std::invalid_argument("a deformable slab of more than " + std::to_string(kMaxCells) + " cells");
  }
  columns_ = cells_along(2.0 * half_size_m.x(), material.cell_m);
  rows_ = cells_along(2.0 * half_size_m.y(), material.cell_m);
  cell_x_m_ = 2.0 * half_size_m.x() / static_cast<double>(columns_);
  cell_y_m_ = 2.0 * half_size_m.y() / static_cast<double>(rows_);
  max_depth_m_ = (1.0 - DeformableMaterial::kUnyieldingFraction) * 2.0 * half_size_m.z();
  depth_m_.assign(columns_ * rows_, 0.0);
  top_m_.assign(columns_ * rows_, half_size_m.z());
  lowest_m_ = half_size_m.z();
  received_Ns_.assign(columns_ * rows_, 0.0);
  if (material.law == DeformableMaterial::Law::elastic) {
    membrane_ = std::make_unique<ElasticMembrane>(material, columns_, rows_, cell_x_m_, cell_y_m_, max_depth_m_);
    force_N_.assign(columns_ * rows_, 0.0);
    pin_m_.assign(columns_ * rows_, std::numeric_limits<double>::quiet_NaN());
  }
}

Eigen::Vector3d DeformableSurface::to_body(const Eigen::Vector3d& world_m) const {
  return orientation_.conjugate() * (world_m - position_m_);
}

bool DeformableSurface::spread(double x_m, double y_m, double amount, std::vector<double>& grid, bool touch) {
  const double radius_m = material_.contact_radius_m;
  const auto first = [](double low_m, double cell_m, double half_m) {
    return static_cast<long>(std::floor((low_m + half_m) / cell_m));
  };
  const long c0 = std::max(0L, first(x_m - radius_m, cell_x_m_, half_size_m_.x()));
  const long c1 = std::min(static_cast<long>(columns_) - 1, first(x_m + radius_m, cell_x_m_, half_size_m_.x()));
  const long r0 = std::max(0L, first(y_m - radius_m, cell_y_m_, half_size_m_.y()));
  const long r1 = std::min(static_cast<long>(rows_) - 1, first(y_m + radius_m, cell_y_m_, half_size_m_.y()));
  if (c0 > c1 || r0 > r1) return false;
  // The pad's pressure: a paraboloid, 1 − r²/a² at a cell's centre (zero beyond a).
  weights_.clear();
  double total = 0.0;
  for (long r = r0; r <= r1; ++r) {
    const double dy = -half_size_m_.y() + (static_cast<double>(r) + 0.5) * cell_y_m_ - y_m;
    for (long c = c0; c <= c1; ++c) {
      const double dx = -half_size_m_.x() + (static_cast<double>(c) + 0.5) * cell_x_m_ - x_m;
      const double weight = std::max(0.0, 1.0 - (dx * dx + dy * dy) / (radius_m * radius_m));
      weights_.push_back(weight);
      total += weight;
    }
  }
  if (!(total > 0.0)) return false;
  std::size_t k = 0;
  for (long r = r0; r <= r1; ++r) {
    for (long c = c0; c <= c1; ++c, ++k) {
      if (weights_[k] > 0.0) grid[static_cast<std::size_t>(r) * columns_ + static_cast<std::size_t>(c)] +=
          amount * weights_[k] / total;
    }
  }
  if (touch) {
    const auto lo_c = static_cast<std::size_t>(c0), hi_c = static_cast<std::size_t>(c1);
    const auto lo_r = static_cast<std::size_t>(r0), hi_r = static_cast<std::size_t>(r1);
    column_lo_ = touched_ ? std::min(column_lo_, lo_c) : lo_c;
    column_hi_ = touched_ ? std::max(column_hi_, hi_c) : hi_c;
    row_lo_ = touched_ ? std::min(row_lo_, lo_r) : lo_r;
    row_hi_ = touched_ ? std::max(row_hi_, hi_r) : hi_r;
    touched_ = true;
  }
  return true;
}

void DeformableSurface::pin_under(const Eigen::Vector3d& body_m, std::vector<double>& pin_m) const {
  // How far the contact is below the undented face: the pad's cells follow it, paraboloid-shaped (the centre by all
  // of it), the deeper pin where two contacts meet.
  const double below_m = half_size_m_.z() - body_m.z();
  if (!(below_m > 0.0)) return;
  const double radius_m = material_.contact_radius_m;
  for (std::size_t r = 0; r < rows_; ++r) {
    const double dy = -half_size_m_.y() + (static_cast<double>(r) + 0.5) * cell_y_m_ - body_m.y();
    if (std::abs(dy) >= radius_m) continue;
    for (std::size_t c = 0; c < columns_; ++c) {
      const double dx = -half_size_m_.x() + (static_cast<double>(c) + 0.5) * cell_x_m_ - body_m.x();
      const double weight = 1.0 - (dx * dx + dy * dy) / (radius_m * radius_m);
      if (!(weight > 0.0)) continue;
      double& pin = pin_m[r * columns_ + c];
      pin = std::isnan(pin) ? below_m * weight : std::max(pin, below_m * weight);
    }
  }
}

DeformableSurface::OwnShare* DeformableSurface::own(std::size_t slot) {
  if (!shared_) {
    // While one endpoint alone has pushed, its share is the whole surface: nothing to keep apart.
    if (!solo_.has_value() || *solo_ == slot) {
      solo_ = slot;
      return nullptr;
    }
    // A second endpoint: the first one's share so far is everything the surface has, this period's pushes too.
    shared_ = true;
    if (own_.size() <= *solo_) own_.resize(*solo_ + 1);
    OwnShare& first = own_[*solo_];
    first.membrane = std::make_unique<ElasticMembrane>(*membrane_);
    first.depth_m = depth_m_;
    first.received_Ns = received_Ns_;
    first.force_N.assign(columns_ * rows_, 0.0);
    first.pin_m = pin_m_;
  }
  if (own_.size() <= slot) own_.resize(slot + 1);
  OwnShare& share = own_[slot];
  if (!share.membrane) {
    share.membrane = std::make_unique<ElasticMembrane>(material_, columns_, rows_, cell_x_m_, cell_y_m_, max_depth_m_);
    share.depth_m.assign(columns_ * rows_, 0.0);
    share.received_Ns.assign(columns_ * rows_, 0.0);
    share.force_N.assign(columns_ * rows_, 0.0);
    share.pin_m.assign(columns_ * rows_, std::numeric_limits<double>::quiet_NaN());
  }
  return &share;
}

void DeformableSurface::press(const PressStroke& stroke, std::size_t slot) {
  if (!(stroke.push_Ns > 0.0)) return;
  const Eigen::Vector3d from_m = to_body(stroke.from_m);
  const Eigen::Vector3d to_m = to_body(stroke.to_m);
  OwnShare* own_share = membrane_ ? own(slot) : nullptr;
  // Points half a cell apart along the stroke, so its push lies along it as finely as the grid can show.
  const double length_m = (to_m - from_m).head<2>().norm();
  constexpr double kMaxPoints = 4096.0;  // a 2 m stroke in one period at 1 mm cells; more shows nothing finer
  const double points = std::clamp(std::ceil(length_m / (0.5 * std::min(cell_x_m_, cell_y_m_))), 1.0, kMaxPoints);
  const auto count = static_cast<std::size_t>(points);
  const double share_Ns = stroke.push_Ns / points;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d at_m = from_m + (static_cast<double>(k) + 0.5) / points * (to_m - from_m);
    if (spread(at_m.x(), at_m.y(), share_Ns, received_Ns_, true)) {
      pressed_Ns_ += share_Ns;
      if (own_share != nullptr) spread(at_m.x(), at_m.y(), share_Ns, own_share->received_Ns, false);
    } else {
      lost_Ns_ += share_Ns;
    }
  }
}

void DeformableSurface::deepen(std::size_t cell, double by_m) {
  double& depth_m = depth_m_[cell];
  const double wanted_m = depth_m + by_m;
  const double area_m2 = cell_x_m_ * cell_y_m_;
  if (wanted_m > max_depth_m_) clamped_m3_ += (wanted_m - max_depth_m_) * area_m2;
  const double new_m = std::min(wanted_m, max_depth_m_);
  volume_m3_ += (new_m - depth_m) * area_m2;
  if (new_m > depth_m) {
    changed_ = true;
    mark_dented(cell % columns_, cell / columns_);
  }
  depth_m = new_m;
  top_m_[cell] = half_size_m_.z() - new_m;
  lowest_m_ = std::min(lowest_m_, top_m_[cell]);
  max_dent_m_ = std::max(max_dent_m_, depth_m);
  dent_m_ = max_dent_m_;
}

void DeformableSurface::mark_dented(std::size_t column, std::size_t row) {
  dented_column_lo_ = dented_ ? std::min(dented_column_lo_, column) : column;
  dented_column_hi_ = dented_ ? std::max(dented_column_hi_, column) : column;
  dented_row_lo_ = dented_ ? std::min(dented_row_lo_, row) : row;
  dented_row_hi_ = dented_ ? std::max(dented_row_hi_, row) : row;
  dented_ = true;
}

void DeformableSurface::remeasure() {
  const double area_m2 = cell_x_m_ * cell_y_m_;
  constexpr double kMoved_m = 1e-9;  // a nanometre: below it a cell is drawn and counted as the undented face
  double deepest_m = 0.0;
  double volume_m3 = 0.0;
  double lowest_m = half_size_m_.z();
  for (std::size_t r = 0; r < rows_; ++r) {
    for (std::size_t c = 0; c < columns_; ++c) {
      const std::size_t cell = r * columns_ + c;
      const double depth_m = depth_m_[cell];
      top_m_[cell] = half_size_m_.z() - depth_m;
      lowest_m = std::min(lowest_m, top_m_[cell]);
      deepest_m = std::max(deepest_m, depth_m);
      volume_m3 += depth_m * area_m2;
      if (std::abs(depth_m) > kMoved_m) mark_dented(c, r);
    }
  }
  lowest_m_ = lowest_m;
  dent_m_ = deepest_m;
  max_dent_m_ = std::max(max_dent_m_, deepest_m);
  volume_m3_ = volume_m3;
}

void DeformableSurface::view_dent(std::int32_t object_id, ViewDent& out) const {
  out.object_id = -1;
  if (!dented_) return;
  // A cell of undented face on each side, so the drawn dent meets the face at its rim; at least two points a side.
  const std::size_t column_lo = dented_column_lo_ > 0 ? dented_column_lo_ - 1 : 0;
  const std::size_t column_hi = std::min(dented_column_hi_ + 1, columns_ - 1);
  const std::size_t row_lo = dented_row_lo_ > 0 ? dented_row_lo_ - 1 : 0;
  const std::size_t row_hi = std::min(dented_row_hi_ + 1, rows_ - 1);
  const std::size_t span_columns = column_hi - column_lo + 1;
  const std::size_t span_rows = row_hi - row_lo + 1;
  if (span_columns < 2 || span_rows < 2) return;  // a slab one cell wide: nothing to draw between points
  // Cells per point, each way: 1 while the span fits.
  const std::size_t block_x = (span_columns + kMaxViewDentSide - 1) / kMaxViewDentSide;
  const std::size_t block_y = (span_rows + kMaxViewDentSide - 1) / kMaxViewDentSide;
  const std::size_t columns = std::max<std::size_t>(2, (span_columns + block_x - 1) / block_x);
  const std::size_t rows = std::max<std::size_t>(2, (span_rows + block_y - 1) / block_y);
  out.object_id = object_id;
  out.columns = static_cast<std::uint32_t>(columns);
  out.rows = static_cast<std::uint32_t>(rows);
  out.version = changes_;
  out.dx_m = static_cast<double>(block_x) * cell_x_m_;
  out.dy_m = static_cast<double>(block_y) * cell_y_m_;
  // Each point at its block's middle.
  out.x0_m = -half_size_m_.x() + (static_cast<double>(column_lo) + 0.5 * static_cast<double>(block_x)) * cell_x_m_;
  out.y0_m = -half_size_m_.y() + (static_cast<double>(row_lo) + 0.5 * static_cast<double>(block_y)) * cell_y_m_;
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns; ++c) {
      double deepest_m = 0.0;
      for (std::size_t br = 0; br < block_y; ++br) {
        const std::size_t row = std::min(row_lo + r * block_y + br, row_hi);
        for (std::size_t bc = 0; bc < block_x; ++bc) {
          const std::size_t column = std::min(column_lo + c * block_x + bc, column_hi);
          deepest_m = std::max(deepest_m, depth_m_[row * columns_ + column]);
        }
      }
      out.depth_m[r * columns + c] = static_cast<float>(deepest_m);
    }
  }
}

DentedTop DeformableSurface::dented_top() const {
  DentedTop top;
  top.columns = columns_;
  top.rows = rows_;
  top.cell_x_m = cell_x_m_;
  top.cell_y_m = cell_y_m_;
  top.height_m = top_m_.data();
  top.floor_m = half_size_m_.z() - max_depth_m_;
  top.lowest_m = lowest_m_;
  return top;
}

void DeformableSurface::press_by_penetration(const Eigen::Vector3d& finger_m, std::size_t slot) {
  const Eigen::Vector3d body_m = to_body(finger_m);
  if (!over_face(body_m)) return;
  if (membrane_) {
    // The share first: a second endpoint's first pin splits the shares, and the first endpoint's takes the pins so far.
    OwnShare* share = own(slot);
    pin_under(body_m, pin_m_);
    if (share != nullptr) pin_under(body_m, share->pin_m);
    pinned_ = true;
    return;
  }
  const double penetration_m = height_m(body_m.x(), body_m.y()) - body_m.z();
  if (!(penetration_m > 0.0)) return;
  const double radius_m = material_.contact_radius_m;
  const double centre_m = material_.plasticity * penetration_m;
  // The cells under the pad only: its bounding square, clamped to the grid (the finger is over the face).
  const auto first = [](double low_m, double cell_m, double half_m, std::size_t count) {
    return static_cast<std::size_t>(std::clamp(std::floor((low_m + half_m) / cell_m), 0.0, count - 1.0));
  };
  const std::size_t c0 = first(body_m.x() - radius_m, cell_x_m_, half_size_m_.x(), columns_);
  const std::size_t c1 = first(body_m.x() + radius_m, cell_x_m_, half_size_m_.x(), columns_);
  const std::size_t r0 = first(body_m.y() - radius_m, cell_y_m_, half_size_m_.y(), rows_);
  const std::size_t r1 = first(body_m.y() + radius_m, cell_y_m_, half_size_m_.y(), rows_);
  for (std::size_t r = r0; r <= r1; ++r) {
    const double dy = -half_size_m_.y() + (static_cast<double>(r) + 0.5) * cell_y_m_ - body_m.y();
    for (std::size_t c = c0; c <= c1; ++c) {
      const double dx = -half_size_m_.x() + (static_cast<double>(c) + 0.5) * cell_x_m_ - body_m.x();
      const double weight = 1.0 - (dx * dx + dy * dy) / (radius_m * radius_m);
      if (weight > 0.0) deepen(r * columns_ + c, centre_m * weight);
    }
  }
  if (changed_) ++changes_;
  changed_ = false;
}

void DeformableSurface::absorb(const Eigen::Vector3d& impulse_Ns) {
  absorbed_Ns_ += std::max(0.0, -impulse_Ns.dot(orientation_ * Eigen::Vector3d::UnitZ()));
}

void DeformableSurface::yield_period(double period_s) {
  if (membrane_) {
    // elastic_membrane.h: the period's pushes as forces held over the coming period, f_c = J_c / T.
    const bool pushed = touched_ && period_s > 0.0;
    if (pushed) {
      for (std::size_t r = row_lo_; r <= row_hi_; ++r) {
        for (std::size_t c = column_lo_; c <= column_hi_; ++c) {
          const std::size_t cell = r * columns_ + c;
          force_N_[cell] = received_Ns_[cell] / period_s;
          received_Ns_[cell] = 0.0;
        }
      }
    }
    if (period_s > 0.0 && membrane_->step(period_s, force_N_, depth_m_, pinned_ ? &pin_m_ : nullptr)) {
      remeasure();
      ++changes_;
    }
    if (pushed) {
      for (std::size_t r = row_lo_; r <= row_hi_; ++r) {
        std::fill_n(force_N_.begin() + static_cast<long>(r * columns_ + column_lo_), column_hi_ - column_lo_ + 1, 0.0);
      }
    }
    touched_ = false;
    // Each endpoint's own share, by the same law from its pushes alone.
    for (OwnShare& share : own_) {
      if (!share.membrane || !(period_s > 0.0)) continue;
      for (std::size_t cell = 0; cell < share.force_N.size(); ++cell) {
        share.force_N[cell] = share.received_Ns[cell] / period_s;
        share.received_Ns[cell] = 0.0;
      }
      share.membrane->step(period_s, share.force_N, share.depth_m, pinned_ ? &share.pin_m : nullptr);
      if (pinned_) std::fill(share.pin_m.begin(), share.pin_m.end(), std::numeric_limits<double>::quiet_NaN());
    }
    if (pinned_) std::fill(pin_m_.begin(), pin_m_.end(), std::numeric_limits<double>::quiet_NaN());
    pinned_ = false;
    return;
  }
  if (!touched_) return;
  const double area_m2 = cell_x_m_ * cell_y_m_;
  // deformable_material.h: Δdepth_c = Σ e_k·w_c / (A·η), the push beyond yield each cell received.
  for (std::size_t r = row_lo_; r <= row_hi_; ++r) {
    for (std::size_t c = column_lo_; c <= column_hi_; ++c) {
      const std::size_t cell = r * columns_ + c;
      const double received_Ns = received_Ns_[cell];
      received_Ns_[cell] = 0.0;
      if (received_Ns > 0.0) deepen(cell, received_Ns / (area_m2 * material_.flow_resistance_Paspm));
    }
  }
  touched_ = false;
  if (changed_) ++changes_;
  changed_ = false;
}

double DeformableSurface::value_at(const std::vector<double>& grid, double x_m, double y_m) const {
  const double fx = std::clamp((x_m + half_size_m_.x()) / cell_x_m_ - 0.5, 0.0, static_cast<double>(columns_ - 1));
  const double fy = std::clamp((y_m + half_size_m_.y()) / cell_y_m_ - 0.5, 0.0, static_cast<double>(rows_ - 1));
  const auto c0 = static_cast<std::size_t>(fx);
  const auto r0 = static_cast<std::size_t>(fy);
  const std::size_t c1 = std::min(c0 + 1, columns_ - 1);
  const std::size_t r1 = std::min(r0 + 1, rows_ - 1);
  const double tx = fx - static_cast<double>(c0);
  const double ty = fy - static_cast<double>(r0);
  const double low = (1.0 - tx) * grid[r0 * columns_ + c0] + tx * grid[r0 * columns_ + c1];
  const double high = (1.0 - tx) * grid[r1 * columns_ + c0] + tx * grid[r1 * columns_ + c1];
  return (1.0 - ty) * low + ty * high;
}

double DeformableSurface::height_m(double x_m, double y_m) const {
  // Bilinear between cell centres, constant beyond the outer centres.
  return half_size_m_.z() - value_at(depth_m_, x_m, y_m);
}

bool DeformableSurface::over_face(const Eigen::Vector3d& body_m) const {
  return std::abs(body_m.x()) <= half_size_m_.x() && std::abs(body_m.y()) <= half_size_m_.y() &&
         body_m.z() >= -half_size_m_.z();
}

void DeformableSurface::tangent_plane(const Eigen::Vector3d& body_m, Eigen::Vector3d& point_m,
                                   Eigen::Vector3d& normal) const {
  const double x_m = std::clamp(body_m.x(), -half_size_m_.x(), half_size_m_.x());
  const double y_m = std::clamp(body_m.y(), -half_size_m_.y(), half_size_m_.y());
  // The slope by central differences half a cell each way: the bilinear surface's own slope there.
  const double hx = 0.5 * cell_x_m_;
  const double hy = 0.5 * cell_y_m_;
  const double slope_x = (height_m(x_m + hx, y_m) - height_m(x_m - hx, y_m)) / (2.0 * hx);
  const double slope_y = (height_m(x_m, y_m + hy) - height_m(x_m, y_m - hy)) / (2.0 * hy);
  point_m = position_m_ + orientation_ * Eigen::Vector3d(x_m, y_m, height_m(x_m, y_m));
  normal = orientation_ * Eigen::Vector3d(-slope_x, -slope_y, 1.0).normalized();
}

void DeformableSurface::patch_about(const Eigen::Vector3d& body_m, std::int32_t object_id, double half_span_m,
                                    DentPatch& patch, std::size_t slot) const {
  constexpr double kHalfSamples = 0.5 * (kDentPatchSide - 1);
  const double wanted_m = std::isfinite(half_span_m) ? std::max(0.0, half_span_m) : 0.0;
  // Across the whole face at most: beyond it the heights are the edge's anyway.
  const double reach_m = std::min(wanted_m, std::max(half_size_m_.x(), half_size_m_.y()) * 2.0);
  const double spacing_m = std::max(std::min(cell_x_m_, cell_y_m_), reach_m / kHalfSamples);
  const double span_m = kHalfSamples * spacing_m;
  double x0_m = body_m.x() - span_m;
  double y0_m = body_m.y() - span_m;
  // Samples a cell apart on square cells lie on the cells' centres: the heights are the cells' own, and the haptic
  // side's bilinear surface between them is this grid's (resampled between centres, it would be smoothed twice).
  if (spacing_m == cell_x_m_ && spacing_m == cell_y_m_) {
    const auto centre = [spacing_m](double low_m, double half_m) {
      return -half_m + (std::round((low_m + half_m) / spacing_m - 0.5) + 0.5) * spacing_m;
    };
    x0_m = centre(x0_m, half_size_m_.x());
    y0_m = centre(y0_m, half_size_m_.y());
  }
  patch.object_id = object_id;
  patch.origin_m = to_vec3(position_m_ + orientation_ * Eigen::Vector3d(x0_m, y0_m, 0.0));
  patch.axis_x = to_vec3(orientation_ * Eigen::Vector3d::UnitX());
  patch.axis_y = to_vec3(orientation_ * Eigen::Vector3d::UnitY());
  patch.spacing_m = spacing_m;
  if (membrane_ && !shared_ && solo_ == slot) {
    // Elastic, the only endpoint that pushed: its share is the whole surface, and the surface without it the face.
    std::fill(patch.height_m.begin(), patch.height_m.end(), half_size_m_.z());
    return;
  }
  for (std::uint32_t j = 0; j < kDentPatchSide; ++j) {
    for (std::uint32_t i = 0; i < kDentPatchSide; ++i) {
      patch.height_m[j * kDentPatchSide + i] = height_m(x0_m + i * spacing_m, y0_m + j * spacing_m);
    }
  }
  if (!membrane_ || slot >= own_.size() || !own_[slot].membrane) return;
  const std::vector<double>& own_m = own_[slot].depth_m;
  for (std::uint32_t j = 0; j < kDentPatchSide; ++j) {
    for (std::uint32_t i = 0; i < kDentPatchSide; ++i) {
      patch.height_m[j * kDentPatchSide + i] += value_at(own_m, x0_m + i * spacing_m, y0_m + j * spacing_m);
    }
  }
}

DeformableSurface::Profile DeformableSurface::deepest_row() const {
  Profile profile;
  const auto deepest = static_cast<std::size_t>(std::max_element(depth_m_.begin(), depth_m_.end()) - depth_m_.begin());
  const std::size_t row = deepest / columns_;
  profile.y_m = -half_size_m_.y() + (static_cast<double>(row) + 0.5) * cell_y_m_;
  profile.x0_m = -half_size_m_.x() + 0.5 * cell_x_m_;
  profile.dx_m = cell_x_m_;
  profile.depth_m.assign(depth_m_.begin() + static_cast<long>(row * columns_),
                         depth_m_.begin() + static_cast<long>((row + 1) * columns_));
  return profile;
}


}  // namespace impetus
