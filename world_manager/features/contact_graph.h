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
//
// Sleeping bodies (the engine stops simulating a body at rest, engine/sleeping_bodies.h): a body put to sleep keeps the contacts it
// had in its last simulated substep (`rest`) until it wakes (`wake`), so the local model sees a resting body on its
// support whether or not the engine simulated it this step. The cost of a step's graph grows with the contacts of the
// bodies simulated, not with the number of bodies.

#include "common/contract/frames.h"
#include "world_manager/object_state.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace impetus {

class ContactGraph {
 public:
  static constexpr std::int32_t kStatic = -1;  // the other side is static geometry (floor, fixed objects)
  // Two contact normals of one object closer than this (cosine) are one constraint for the local model: the four
  // corner contacts of a box resting on the floor are one support.
  static constexpr double kSameContactCosine = 0.999;

  // Forget the contacts of the last substep (not those of sleeping bodies); bodies are 0 … body_count − 1.
  void reset(std::size_t body_count);

  // One contact point: `normal` (unit) pushes `body` out of `other` (a body id or kStatic); `friction` is the pair's μ;
  // `normal_force_N` what the contact pushed with in its substep (≥ 0; 0 when unknown).
  void add(std::int32_t body, std::int32_t other, const Eigen::Vector3d& normal, double friction,
           double normal_force_N = 0.0);

  // After the last add(): index the contacts by body. O(C log C) in the contacts added.
  void finish();

  // `body` has gone to sleep: its contacts as of the last finish() stay its contacts until wake(body).
  void rest(std::int32_t body);
  // `body` is simulated again: the next reset() forgets its sleeping contacts, and finish() gives its new ones.
  void wake(std::int32_t body);

  // `body`'s contacts for the local model: merged by direction (normals within kSameContactCosine are one constraint,
  // e.g. the four corners of a box on the floor), at most kMaxLocalContacts, kContactHolds set where the other side
  // holds. Returns the count.
  // A contact with a dynamic body carries that body's velocity and inverse mass from `states` (its inertia in the
  // local model); merged contacts carry the heaviest of their bodies.
  std::uint32_t local_contacts(std::int32_t body, std::span<const ObjectState> states,
                               std::array<LocalContact, kMaxLocalContacts>& out);

  // Whether `body` had any contact (after finish()).
  bool touching(std::int32_t body) const { return !edges_of(body).empty(); }

  // Σ μ·N over `body`'s contacts (N: each contact's normal force in the recorded substep): the most tangential force
  // its contacts' friction can hold (N). 0 for a body without contacts or with unknown forces.
  double friction_capacity_N(std::int32_t body) const;

  // The weight `weight_N` less what `body`'s contacts carry of it: the part along the contacts' mean normal (Σ N·n,
  // each contact's normal force on it) taken off where they push against it. A body on a slope keeps its weight's
  // part along the slope; one on a floor keeps none; one without contacts or with unknown forces keeps all of it.
  Eigen::Vector3d unsupported_weight_N(std::int32_t body, const Eigen::Vector3d& weight_N) const;

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
  struct BodyEdges {
    std::int32_t body;
    std::size_t begin, end;  // range in edges_
  };

  // `body`'s contacts: its sleeping ones if it sleeps, else those of the last finish().
  std::span<const Edge> edges_of(std::int32_t body) const;

  std::size_t body_count_ = 0;
  std::vector<PendingEdge> pending_;
  std::vector<Edge> edges_;             // grouped by body after finish()
  std::vector<BodyEdges> index_;        // the bodies with contacts, ascending
  std::unordered_map<std::int32_t, std::vector<Edge>> resting_;  // sleeping bodies' contacts
  std::vector<std::int32_t> woken_;     // bodies whose sleeping contacts the next reset() forgets
  std::vector<std::uint32_t> visited_;   // per body: the query generation that last visited it
  std::uint32_t generation_ = 0;
  std::vector<std::int32_t> stack_;
};

}  // namespace impetus
