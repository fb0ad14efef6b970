// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/sleeping_bodies.h"

#include "world_manager/features/contact_graph.h"

#include <algorithm>

namespace impetus {

SleepingBodies::SleepingBodies(std::size_t object_count, double cell_size_m, const EscapeGuard& escape_guard,
                               ContactGraph& contacts)
    : kind_(object_count, Kind::fixed),
      resting_bounds_(object_count),
      grid_(cell_size_m),
      escape_guard_(&escape_guard),
      contacts_(&contacts) {
  grid_.reset(object_count);
}

void SleepingBodies::add_fixed(std::size_t id, const Eigen::AlignedBox3d& bounds) {
  kind_[id] = Kind::fixed;
  resting_bounds_[id] = bounds;
  grid_.update(static_cast<std::int32_t>(id), bounds);
}

void SleepingBodies::add_awake(std::size_t id) {
  kind_[id] = Kind::awake;
  awake_.push_back(id);
  moved_.push_back(id);  // every dynamic body before the first step
}

void SleepingBodies::fixed_near(const Eigen::AlignedBox3d& box, std::vector<std::size_t>& out) const {
  out.clear();
  grid_.query(box, nearby_);
  for (const std::int32_t other : nearby_) {
    const auto o = static_cast<std::size_t>(other);
    if (kind_[o] == Kind::fixed && box.intersects(resting_bounds_[o])) out.push_back(o);
  }
}

void SleepingBodies::begin_step() {
  moved_.assign(awake_.begin(), awake_.end());
  std::sort(moved_.begin(), moved_.end());
}

void SleepingBodies::wake(std::size_t id, Engine& engine) {
  if (kind_[id] != Kind::asleep) return;
  engine.enter_solver(id);
  grid_.remove(static_cast<std::int32_t>(id));
  kind_[id] = Kind::awake;
  awake_.push_back(id);
  const auto at = std::lower_bound(moved_.begin(), moved_.end(), id);
  if (at == moved_.end() || *at != id) moved_.insert(at, id);
  contacts_->wake(static_cast<std::int32_t>(id));
}

void SleepingBodies::wake_touched(double substep_s, Engine& engine) {
  wake_queue_.assign(awake_.begin(), awake_.end());
  for (std::size_t i = 0; i < wake_queue_.size(); ++i) {
    const std::size_t id = wake_queue_[i];
    if (escape_guard_->escaped(id)) continue;
    const Eigen::AlignedBox3d reach = engine.reach_bounds(id, substep_s);
    grid_.query(reach, nearby_);
    for (const std::int32_t other : nearby_) {
      const auto o = static_cast<std::size_t>(other);
      if (kind_[o] != Kind::asleep || !reach.intersects(resting_bounds_[o])) continue;
      if (!engine.reaches(id, o)) continue;
      wake(o, engine);
      wake_queue_.push_back(o);
    }
  }
}

void SleepingBodies::put_rested_to_sleep(Engine& engine) {
  std::size_t kept = 0;
  for (const std::size_t id : awake_) {
    if (escape_guard_->escaped(id)) continue;
    if (engine.rested(id)) {
      engine.leave_solver(id);
      kind_[id] = Kind::asleep;
      resting_bounds_[id] = engine.bounds(id);
      grid_.update(static_cast<std::int32_t>(id), resting_bounds_[id]);
      contacts_->rest(static_cast<std::int32_t>(id));
      continue;
    }
    awake_[kept++] = id;
  }
  awake_.resize(kept);
}

}  // namespace impetus
