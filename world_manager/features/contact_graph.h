// SPDX-License-Identifier: Apache-2.0
#pragma once
// The contacts among bodies in the world's last substep, as the haptic side's local model needs them (paper §6.3,
// haptic_controller/local_dynamics.h): per body, its contact normals merged by direction, each flagged whether the
// other side can *hold* a push.
//
// Why the flag: the local model moves a pushed body between world frames, and its contacts are the constraints. A
// contact with the floor holds any push into it. A contact with another body holds only if that body cannot give
// way: if the model takes a loose 3 g ball's neighbour as immovable, the finger presses a plane that does not yield,
// the world then moves ball and neighbour with the whole impulse, and the energy comes from nowhere (hard case 10).
// A neighbour holds a push along d when a chain of contacts, each able to take d without sliding (d within the
// contact's friction cone: the angle between d and −n at most atan μ), reaches static geometry: a stack pressed from
// above holds, a loose row of balls pushed sideways does not. Loose contacts still carry the body's weight in the
// model (the world's state is in equilibrium under gravity), just not the finger's push.
//
// The chain test keeps the push direction fixed along the chain (a contact's friction cone is the tolerance): it
// errs toward "does not hold", i.e. toward a model that gives way more than the world does, which is the passive
// error (local_dynamics.h, frame boundaries).

#include "common/contract/frames.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace impetus {

class ContactGraph {
 public:
  static constexpr std::int32_t kStatic = -1;  // the other side is static geometry (floor, fixed objects)

  // Forget the contacts; bodies are 0 … body_count − 1.
  void reset(std::size_t body_count);

  // One contact point: `normal` (unit) pushes `body` out of `other` (a body id or kStatic); `friction` is the pair's μ;
  // `normal_force_N` what the contact pushed with in its substep (≥ 0; 0 when unknown).
  void add(std::int32_t body, std::int32_t other, const Eigen::Vector3d& normal, double friction,
           double normal_force_N = 0.0);

  // After the last add(): index the contacts by body.
  void finish();

  // `body`'s contacts for the local model: merged by direction (normals within kSameContactCosine are one constraint,
  // e.g. the four corners of a box on the floor), at most kMaxLocalContacts, kContactHolds set where the other side
  // holds. Returns the count.
  // A contact with a dynamic body carries that body's velocity and inverse mass from `states` (its inertia in the
  // local model); merged contacts carry the heaviest of their bodies.
  std::uint32_t local_contacts(std::int32_t body, std::span<const ObjectState> states,
                               std::array<LocalContact, kMaxLocalContacts>& out);

  // Whether `body` had any contact (after finish()).
  bool touching(std::int32_t body) const {
    return body >= 0 && static_cast<std::size_t>(body) < body_count_ &&
           first_edge_[static_cast<std::size_t>(body) + 1] > first_edge_[static_cast<std::size_t>(body)];
  }

  // Σ μ·N over `body`'s contacts (N: each contact's normal force in the recorded substep): the most tangential force
  // its contacts' friction can hold (N). 0 for a body without contacts or with unknown forces.
  double friction_capacity_N(std::int32_t body) const;

  // Whether `body`, pushed along `direction` (unit), is held by a chain of contacts to static geometry (header).
  bool holds(std::int32_t body, const Eigen::Vector3d& direction);

 private:
  struct Edge {
    std::int32_t other;
    Eigen::Vector3d normal;
    double friction;
    double normal_force_N;
  };
  struct PendingEdge {
    std::int32_t body;
    Edge edge;
  };

  std::size_t body_count_ = 0;
  std::vector<PendingEdge> pending_;
  std::vector<Edge> edges_;             // grouped by body after finish()
  std::vector<std::size_t> first_edge_;  // body → index of its first edge in edges_; size body_count + 1
  std::vector<std::size_t> cursor_;     // finish()'s fill position per body (kept to reuse its storage)
  std::vector<std::uint32_t> visited_;   // per body: the query generation that last visited it
  std::uint32_t generation_ = 0;
  std::vector<std::int32_t> stack_;
};

}  // namespace impetus
