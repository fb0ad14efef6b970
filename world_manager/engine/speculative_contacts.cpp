// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/speculative_contacts.h"

#include "world_manager/engine/sleeping_bodies.h"
#include "world_manager/scene.h"

#include <algorithm>
#include <cmath>

namespace impetus {
namespace {

// A pair as one key, the lower id first.
std::uint64_t pair_key(std::size_t a, std::size_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
}

}  // namespace

SpeculativeContacts::SpeculativeContacts(std::size_t object_count, bool floor_present,
                                         const Eigen::Vector3d& gravity_mps2, const std::vector<Material>& materials,
                                         const EscapeGuard& escape_guard, const SleepingBodies* sleeping)
    : object_count_(object_count),
      floor_present_(floor_present),
      gravity_mps2_(gravity_mps2),
      materials_(&materials),
      escape_guard_(&escape_guard),
      sleeping_(sleeping),
      displacement_(object_count, Eigen::Vector3d::Zero()) {}

void SpeculativeContacts::add_fixed(std::size_t id, const Eigen::AlignedBox3d& bounds) {
  fixed_bounds_.emplace_back(id, bounds);
}

void SpeculativeContacts::begin_substep(double substep_s) {
  touching_.clear();
  substep_s_ = substep_s;
}

Eigen::Vector3d SpeculativeContacts::free_displacement(std::size_t id, double h, const Engine& engine) const {
  const std::optional<Motion> motion = engine.motion(id);
  if (!motion) return Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration = motion->force_N / motion->mass_kg;
  if (motion->gravity) acceleration += gravity_mps2_;
  return h * (motion->velocity_mps + h * acceleration);
}

void SpeculativeContacts::predict(const std::vector<std::size_t>& movers, const Engine& engine) {
  for (const std::size_t id : movers) {
    if (escape_guard_->escaped(id)) continue;
    const std::optional<Motion> motion = engine.motion(id);
    if (!motion || motion->stopped) continue;
    displacement_[id] = free_displacement(id, substep_s_, engine);
  }
}

Eigen::Vector3d SpeculativeContacts::displacement_of(std::size_t id, const Engine& engine) const {
  if (id >= object_count_ || escape_guard_->escaped(id)) return Eigen::Vector3d::Zero();
  const std::optional<Motion> motion = engine.motion(id);
  if (!motion || motion->stopped) return Eigen::Vector3d::Zero();
  return displacement_[id];
}

Eigen::AlignedBox3d SpeculativeContacts::swept_bounds(std::size_t id, const Engine& engine) const {
  Eigen::AlignedBox3d bounds = engine.bounds(id);
  Eigen::AlignedBox3d moved_bounds = bounds;
  return bounds.extend(moved_bounds.translate(displacement_[id]));
}

bool SpeculativeContacts::meets(std::size_t id, std::size_t other, Engine& engine) const {
  Point found[kMaxContactsPerPair];
  return carry_back(displacement_[id], found, engine.collide_displaced(id, other, displacement_[id], found)) > 0;
}

Eigen::Vector3d SpeculativeContacts::point_velocity(std::size_t id, const Eigen::Vector3d& at,
                                                    const Engine& engine) const {
  if (id >= object_count_) return Eigen::Vector3d::Zero();
  const std::optional<Motion> motion = engine.motion(id);
  if (!motion) return Eigen::Vector3d::Zero();
  return motion->velocity_mps + motion->angular_velocity_radps.cross(at - motion->position_m);
}

bool SpeculativeContacts::defer_touching(std::size_t a, std::size_t b, const Point& first, const Engine& engine) {
  touching_.push_back(pair_key(a, b));
  const double closing_mps =
      -first.normal.dot(point_velocity(a, first.position_m, engine) - point_velocity(b, first.position_m, engine));
  if (!(closing_mps > kBounceThreshold_mps)) return false;
  closing_.emplace_back(a, b);
  return true;
}

void SpeculativeContacts::add_closing_contacts(Engine& engine) {
  for (const auto& [a, b] : closing_) {
    if (add_swept_contacts(a, b, engine)) continue;
    engine.add_ordinary_contacts(a, b);
  }
  closing_.clear();
}

int SpeculativeContacts::carry_back(const Eigen::Vector3d& displacement_m, Point* points, int count) {
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const Point overlap = points[i];
    // The overlap along n at the moved pose is depth; moving back by d changes it by d·n (n pushes the moved body
    // out), so at the start the pair is apart by gap = −depth − d·n.
    const double gap_m = -overlap.depth_m - displacement_m.dot(overlap.normal);
    if (!std::isfinite(gap_m)) continue;
    Point& carried = points[kept++];
    carried.position_m = overlap.position_m - displacement_m - 0.5 * gap_m * overlap.normal;
    carried.normal = overlap.normal;
    carried.depth_m = -gap_m;
  }
  return kept;
}

bool SpeculativeContacts::add_swept_contacts(std::size_t a, std::size_t b, Engine& engine) {
  // The moved one is a body the solver holds, the lower id if both are.
  const bool a_body = a < object_count_ && engine.motion(a).has_value();
  const bool b_body = b < object_count_ && engine.motion(b).has_value();
  if (!a_body || (b_body && b < a)) std::swap(a, b);
  const Eigen::Vector3d relative_m = displacement_of(a, engine) - displacement_of(b, engine);
  if (!(relative_m.squaredNorm() > 0.0)) return false;
  Point found[kMaxContactsPerPair];
  const int count = carry_back(relative_m, found, engine.collide_displaced(a, b, relative_m, found));
  const double restitution = combine_restitution((*materials_)[a].restitution, (*materials_)[b].restitution);
  for (int i = 0; i < count; ++i) {
    Row row;
    row.point = found[i];
    const double gap_m = -row.point.depth_m;
    row.speculative = gap_m > 0.0;
    if (row.speculative) {
      row.point.depth_m = 0.0;
      row.normal_speed_mps = -gap_m / substep_s_;
      if (restitution > 0.0) {
        const double closing_mps = -row.point.normal.dot(point_velocity(a, row.point.position_m, engine) -
                                                         point_velocity(b, row.point.position_m, engine));
        if (closing_mps > kBounceThreshold_mps) row.normal_speed_mps = restitution * closing_mps;
      }
    }
    engine.add_row(a, b, row);
  }
  return count > 0;
}

void SpeculativeContacts::speculate_pair(std::size_t id, std::size_t other, Engine& engine) {
  if (other < object_count_ && escape_guard_->escaped(other)) return;  // parked: collides with nothing
  if (std::binary_search(touching_.begin(), touching_.end(), pair_key(id, other))) return;
  add_swept_contacts(id, other, engine);
}

void SpeculativeContacts::speculate(const std::vector<std::size_t>& movers, Engine& engine) {
  std::sort(touching_.begin(), touching_.end());
  sweeps_.clear();
  for (const std::size_t id : movers) {
    if (escape_guard_->escaped(id)) continue;
    const std::optional<Motion> motion = engine.motion(id);
    if (!motion || motion->stopped) continue;
    sweeps_.push_back({id, swept_bounds(id, engine)});
  }
  std::sort(sweeps_.begin(), sweeps_.end(),
            [](const Sweep& a, const Sweep& b) { return a.bounds.min().x() < b.bounds.min().x(); });
  const std::size_t floor_id = object_count_;
  for (std::size_t i = 0; i < sweeps_.size(); ++i) {
    const Sweep& a = sweeps_[i];
    for (std::size_t j = i + 1; j < sweeps_.size() && sweeps_[j].bounds.min().x() <= a.bounds.max().x(); ++j) {
      if (!a.bounds.intersects(sweeps_[j].bounds)) continue;
      speculate_pair(std::min(a.id, sweeps_[j].id), std::max(a.id, sweeps_[j].id), engine);
    }
    if (floor_present_) speculate_pair(a.id, floor_id, engine);
    if (sleeping_ != nullptr) {
      sleeping_->fixed_near(a.bounds, nearby_);
      for (const std::size_t o : nearby_) speculate_pair(a.id, o, engine);
    } else {
      for (const auto& [o, bounds] : fixed_bounds_) {
        if (a.bounds.intersects(bounds)) speculate_pair(a.id, o, engine);
      }
    }
  }
}

}  // namespace impetus
