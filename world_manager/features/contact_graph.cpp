// SPDX-License-Identifier: Apache-2.0
#include "world_manager/features/contact_graph.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace impetus {
namespace {

// Rounding slack of the friction-cone test: ODE's box–box normals are axis-aligned to ~1e-16, and a push exactly along
// a frictionless contact's normal must count as held.
constexpr double kConeSlack = 1e-9;

}  // namespace

void ContactGraph::reset(std::size_t body_count) {
  body_count_ = body_count;
  pending_.clear();
  edges_.clear();
  index_.clear();
  for (const std::int32_t body : woken_) resting_.erase(body);
  woken_.clear();
  if (visited_.size() != body_count) visited_.assign(body_count, 0);
}

void ContactGraph::add(std::int32_t body, std::int32_t other, const Eigen::Vector3d& normal, double friction,
                       double normal_force_N) {
  if (body < 0 || static_cast<std::size_t>(body) >= body_count_) return;
  if (other != kStatic && (other < 0 || static_cast<std::size_t>(other) >= body_count_)) return;
  if (!(normal.squaredNorm() > 0.0) || !normal.allFinite() || !std::isfinite(friction)) return;
  const double force_N = std::isfinite(normal_force_N) ? std::max(0.0, normal_force_N) : 0.0;
  pending_.push_back({body, {other, normal.normalized(), std::max(0.0, friction), force_N}});
}

void ContactGraph::finish() {
  // Grouped by body; within a body the order of add() (stable), so a run is reproducible.
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const PendingEdge& a, const PendingEdge& b) { return a.body < b.body; });
  edges_.clear();
  index_.clear();
  for (const PendingEdge& p : pending_) {
    if (index_.empty() || index_.back().body != p.body) index_.push_back({p.body, edges_.size(), edges_.size()});
    edges_.push_back(p.edge);
    index_.back().end = edges_.size();
  }
}

void ContactGraph::rest(std::int32_t body) {
  woken_.erase(std::remove(woken_.begin(), woken_.end(), body), woken_.end());
  const std::span<const Edge> edges = edges_of(body);
  std::vector<Edge> kept(edges.begin(), edges.end());  // edges_of may point into resting_ itself
  resting_[body] = std::move(kept);
}

void ContactGraph::wake(std::int32_t body) {
  if (resting_.count(body) != 0) woken_.push_back(body);
}

std::span<const ContactGraph::Edge> ContactGraph::edges_of(std::int32_t body) const {
  if (body < 0 || static_cast<std::size_t>(body) >= body_count_) return {};
  if (!resting_.empty()) {
    const auto sleeping = resting_.find(body);
    if (sleeping != resting_.end()) return sleeping->second;
  }
  const auto found = std::lower_bound(index_.begin(), index_.end(), body,
                                      [](const BodyEdges& entry, std::int32_t b) { return entry.body < b; });
  if (found == index_.end() || found->body != body) return {};
  return std::span<const Edge>(edges_).subspan(found->begin, found->end - found->begin);
}

double ContactGraph::friction_capacity_N(std::int32_t body) const {
  double capacity_N = 0.0;
  for (const Edge& edge : edges_of(body)) capacity_N += edge.friction * edge.normal_force_N;
  return capacity_N;
}

Eigen::Vector3d ContactGraph::unsupported_weight_N(std::int32_t body, const Eigen::Vector3d& weight_N) const {
  Eigen::Vector3d support = Eigen::Vector3d::Zero();
  for (const Edge& edge : edges_of(body)) support += edge.normal_force_N * edge.normal;
  const double norm = support.norm();
  if (!(norm > 0.0)) return weight_N;
  const Eigen::Vector3d n = support / norm;
  const double into_support_N = weight_N.dot(n);
  return into_support_N < 0.0 ? Eigen::Vector3d(weight_N - into_support_N * n) : weight_N;
}

bool ContactGraph::holds(std::int32_t body, const Eigen::Vector3d& direction) {
  if (body < 0 || static_cast<std::size_t>(body) >= body_count_) return false;
  if (++generation_ == 0) {  // wrapped: clear the marks once every 2^32 queries
    std::fill(visited_.begin(), visited_.end(), 0u);
    generation_ = 1;
  }
  stack_.clear();
  stack_.push_back(body);
  visited_[static_cast<std::size_t>(body)] = generation_;
  while (!stack_.empty()) {
    const std::int32_t b = stack_.back();
    stack_.pop_back();
    for (const Edge& edge : edges_of(b)) {
      // The contact takes a push along `direction` without sliding iff the push is within its friction cone about
      // −n: cos(angle) ≥ cos(atan μ) = 1/√(1 + μ²).
      const double opposing = -edge.normal.dot(direction);
      if (opposing < 1.0 / std::sqrt(1.0 + edge.friction * edge.friction) - kConeSlack) continue;
      if (edge.other == kStatic) return true;
      const auto next = static_cast<std::size_t>(edge.other);
      if (visited_[next] == generation_) continue;
      visited_[next] = generation_;
      stack_.push_back(edge.other);
    }
  }
  return false;
}

std::uint32_t ContactGraph::local_contacts(std::int32_t body, std::span<const ObjectState> states,
                                          std::array<LocalContact, kMaxLocalContacts>& out) {
  std::uint32_t count = 0;
  for (const Edge& edge : edges_of(body)) {
    // This body pushes the other side along −n.
    const bool held = edge.other == kStatic || holds(edge.other, -edge.normal);
    Vec3 other_velocity_mps{};
    double other_inverse_mass_per_kg = 0.0;
    if (edge.other != kStatic && static_cast<std::size_t>(edge.other) < states.size()) {
      const ObjectState& other = states[static_cast<std::size_t>(edge.other)];
      other_velocity_mps = to_vec3(other.velocity_mps);
      other_inverse_mass_per_kg = other.inverse_mass_per_kg;
    }
    bool merged = false;
    for (std::uint32_t c = 0; c < count && !merged; ++c) {
      LocalContact& known = out[c];
      if (to_eigen(known.normal).dot(edge.normal) > ContactGraph::kSameContactCosine) {
        known.friction = std::max(known.friction, edge.friction);
        if (held) known.flags |= kContactHolds;
        if (other_inverse_mass_per_kg < known.other_inverse_mass_per_kg) {  // the heavier body
          known.other_inverse_mass_per_kg = other_inverse_mass_per_kg;
          known.other_velocity_mps = other_velocity_mps;
        }
        merged = true;
      }
    }
    if (!merged && count < kMaxLocalContacts) {
      out[count++] = {to_vec3(edge.normal), edge.friction, other_velocity_mps, other_inverse_mass_per_kg,
                      held ? kContactHolds : 0u};
    }
  }
  return count;
}

}  // namespace impetus
