// SPDX-License-Identifier: Apache-2.0
#pragma once
// Speculative contacts, an engine-neutral world service (docs/architecture.md §7): the contacts a pair that does not
// touch yet would make within the next substep.
//
// A rigid body steps by v·h. A body that reaches another in the middle of a substep ends it inside, up to v·h deep
// (3.8 mm for a 0.76 m/s cube at 5 ms), and a penetration-correcting solver then pushes the two apart at about
// ERP·v/2 at any substep length: a separating speed no restitution asked for, which the contact never takes back.
// A speculative contact is made one substep early, where the pair is still apart by `gap`, and lets the two close
// at most that gap in the substep: the solver's row is relative normal speed ≥ −gap/h. If the pair would not reach
// it stays inactive (no force); if it would, the pair meets exactly at the surface with the momentum exchange of a
// contact, and nothing is left to correct.
//
// Found by moving the body by its free displacement for the substep (its velocity after gravity and the applied
// forces, times h) and colliding it there: each contact point of that overlap, carried back by the displacement, is
// a point where the pair closes along the contact normal. Translation only: the turn within one substep is left to
// ordinary contacts.
//
// The service decides which pairs to test (a sweep and prune over the moving bodies' swept bounds, fixed geometry
// from a list or from the sleeping bodies' grid, the floor) and what each contact row asks; the engine collides
// geometry and makes rows (SpeculativeContacts::Engine). Ids are scene object indices; the floor is id object_count.
// Used from the world's thread.

#include "world_manager/engine/escape_guard.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace impetus {

class SleepingBodies;
struct Material;

// Below this approach speed a contact does not bounce: resting and sliding objects would otherwise chatter on every
// substep's tiny penetration-correction velocity (ERP pushes at a few mm/s). Every engine's bounce threshold.
inline constexpr double kBounceThreshold_mps = 0.05;

// Contact points an engine may return per pair: box–box needs up to 8 for a face resting on a face.
inline constexpr int kMaxContactsPerPair = 8;

class SpeculativeContacts {
 public:
  // One contact point of a pair (a, b), world frame: `normal` (unit) pushes a out of b, `depth_m` the overlap along it
  // (< 0: still apart by −depth).
  struct Point {
    Eigen::Vector3d position_m;
    Eigen::Vector3d normal;
    double depth_m = 0.0;
  };
  // What the solver's row of one contact asks.
  struct Row {
    Point point;
    // The pair is still apart (point.depth_m is then 0): the row holds the pair's relative normal speed (separating
    // positive) ≥ normal_speed_mps, adds no penetration correction and no bounce of the engine's own (the target
    // carries it), and its force says whether the pair met (none: it did not). Otherwise an ordinary contact.
    bool speculative = false;
    double normal_speed_mps = 0.0;
  };
  // A body as the solver has it now, before this substep's integration.
  struct Motion {
    Eigen::Vector3d position_m;       // centre of mass
    Eigen::Vector3d velocity_mps;
    Eigen::Vector3d angular_velocity_radps;
    Eigen::Vector3d force_N;          // accumulated for this substep (couplings add theirs before it)
    double mass_kg = 0.0;
    bool gravity = true;              // whether gravity acts on it
    bool stopped = false;             // the engine holds it but does not integrate it (rest rule, parked)
  };

  // What the service asks of an engine.
  class Engine {
   public:
    virtual ~Engine() = default;
    // Object `id`'s motion if the solver holds it as a body (awake; `stopped` if it is not integrated this substep);
    // nothing for fixed geometry, the floor and sleeping bodies.
    virtual std::optional<Motion> motion(std::size_t id) const = 0;
    // The box `id`'s collision geometry occupies now.
    virtual Eigen::AlignedBox3d bounds(std::size_t id) const = 0;
    // The contact points of `id`'s geometry, moved by `displacement_m`, against `other`'s as it is (at most
    // kMaxContactsPerPair into `out`); `id`'s state is left exactly as it was. Returns the count.
    virtual int collide_displaced(std::size_t id, std::size_t other, const Eigen::Vector3d& displacement_m,
                                  Point* out) = 0;
    // A contact row between `a` and `b` with the two materials combined, for this substep.
    virtual void add_row(std::size_t a, std::size_t b, const Row& row) = 0;
    // The pair's ordinary contacts (those of where it is now), as the engine makes them without this service.
    virtual void add_ordinary_contacts(std::size_t a, std::size_t b) = 0;
  };

  // `gravity_mps2` the scene's; `materials` per id, the floor last (both outlive the service). `escape_guard`: parked
  // bodies are never tested. `sleeping` (may be null) holds fixed geometry and sleeping bodies; without it, the fixed
  // objects are those given by add_fixed().
  SpeculativeContacts(std::size_t object_count, bool floor_present, const Eigen::Vector3d& gravity_mps2,
                      const std::vector<Material>& materials, const EscapeGuard& escape_guard,
                      const SleepingBodies* sleeping);

  // A fixed object with its bounds (only without sleeping).
  void add_fixed(std::size_t id, const Eigen::AlignedBox3d& bounds);

  // Starts a substep of `substep_s`: forgets the pairs that touched in the last one.
  void begin_substep(double substep_s);
  // The displacement body `id` makes in a substep of h if nothing touches it: semi-implicit Euler (velocity first,
  // then position), with gravity and the forces applied so far. Zero for what the solver does not integrate.
  Eigen::Vector3d free_displacement(std::size_t id, double h, const Engine& engine) const;
  // Stores every moving body's free displacement for this substep (`movers`: the candidates, in order).
  void predict(const std::vector<std::size_t>& movers, const Engine& engine);
  // The bounds `id` sweeps this substep (after predict(), or after remember() for `id`).
  Eigen::AlignedBox3d swept_bounds(std::size_t id, const Engine& engine) const;
  // Stores `displacement_m` as `id`'s for this substep.
  void remember(std::size_t id, const Eigen::Vector3d& displacement_m) { displacement_[id] = displacement_m; }
  // Whether `id`, moved by its stored displacement, would meet `other` (which does not move) in this substep.
  bool meets(std::size_t id, std::size_t other, Engine& engine) const;

  // The engine found pair (a, b) touching, `first` its first contact point: whether the engine must leave its
  // contacts to add_closing_contacts(), because the pair is closing faster than a resting contact ever does (it has
  // only just met; an engine's contacts of a pair touching by a hair are any subset of its corners, e.g. two bottom
  // corners of a face: a torque that pitches both boxes). Either way the pair is not speculated on.
  bool defer_touching(std::size_t a, std::size_t b, const Point& first, const Engine& engine);
  // The deferred pairs: the contacts of where they will be, or their ordinary ones if the displacements part them.
  void add_closing_contacts(Engine& engine);
  // Speculative contacts of every moving body of `movers` (in order) with what it would reach in this substep and
  // does not touch yet: moving pairs by sweep and prune along x (O(n log n) in the bodies that move), fixed geometry
  // from the grid or the list, and the floor.
  void speculate(const std::vector<std::size_t>& movers, Engine& engine);

  // The rows pair (a, b) makes within this substep, moving the one the solver integrates (the lower id if both are)
  // by their relative free displacement: false if they do not meet. Where the pair is still apart by gap the row lets
  // it close the gap and no more (relative normal speed ≥ −gap/h); a bouncing pair (restitution e, closing faster than
  // the bounce threshold) leaves at e times its closing speed from there, as the engine's bounce would one substep
  // later from inside. Where it already overlaps, an ordinary contact.
  bool add_swept_contacts(std::size_t a, std::size_t b, Engine& engine);

  // The contact points of `id` moved by `displacement_m` against `other`, carried back to where the pair is at the
  // substep's start: `position_m` midway across the gap, `depth_m` = −gap (< 0 while still apart). Points whose gap is
  // not finite are dropped. Returns the count.
  static int carry_back(const Eigen::Vector3d& displacement_m, Point* points, int count);

 private:
  struct Sweep {
    std::size_t id;
    Eigen::AlignedBox3d bounds;
  };
  Eigen::Vector3d displacement_of(std::size_t id, const Engine& engine) const;
  Eigen::Vector3d point_velocity(std::size_t id, const Eigen::Vector3d& at, const Engine& engine) const;
  void speculate_pair(std::size_t id, std::size_t other, Engine& engine);

  std::size_t object_count_;
  bool floor_present_;
  Eigen::Vector3d gravity_mps2_;
  const std::vector<Material>* materials_;
  const EscapeGuard* escape_guard_;
  const SleepingBodies* sleeping_;
  double substep_s_ = 0.0;
  std::vector<Eigen::Vector3d> displacement_;  // per object: its free displacement in this substep (moving bodies)
  std::vector<std::uint64_t> touching_;        // pair keys of every pair with ordinary contacts in this substep
  std::vector<std::pair<std::size_t, std::size_t>> closing_;  // touching pairs still closing fast
  std::vector<Sweep> sweeps_;                                 // scratch: the moving bodies' swept bounds
  std::vector<std::pair<std::size_t, Eigen::AlignedBox3d>> fixed_bounds_;  // without sleeping
  std::vector<std::size_t> nearby_;                                        // scratch
};

}  // namespace impetus
