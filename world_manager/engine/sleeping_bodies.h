// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sleeping bodies, an engine-neutral world service (docs/architecture.md §7; scene physics.auto_disable).
//
// The engine's rest rule decides when a body rests (every engine uses the thresholds below); such a body is then
// taken out of the solver altogether, its geometry left in place as fixed geometry in a grid (features/spatial_grid.h).
// Solvers walk every body they hold in every substep, resting or not, and broadphases collide every geometry they
// hold; so a resting body left in the engine would still cost per substep. Each substep the awake bodies are tested
// against the grid: a sleeping body an awake one touches (or, with speculative contacts, would reach within the
// substep) wakes (a body again, with the same mass and pose, at rest) before the contacts are made, as the solver's
// islands would wake it, and its contacts then join the step. A step costs what is awake and what it touches, not
// what exists.
//
// The service keeps which object is fixed, awake or asleep, the grid, and the list of bodies a step moved; the engine
// takes bodies out of its solver and puts them back (SleepingBodies::Engine). Ids are scene object indices. Used from
// the world's thread.

#include "world_manager/engine/escape_guard.h"
#include "world_manager/features/spatial_grid.h"

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace impetus {

class ContactGraph;

class SleepingBodies {
 public:
  // The rest rule: a body rests once its speeds have stayed under these for kRestBeforeSleep_s. 0.01 m/s and
  // 0.01 rad/s (a 5 cm cube's corner moves 0.25 mm/s) are far below anything the haptic side renders. Half a second
  // is ten 20 Hz world periods: a body bouncing or rocking to rest is not frozen mid-motion, and one that a finger
  // keeps pushing is woken by each push (RigidBodyEngine::wake).
  static constexpr double kSleepSpeed_mps = 0.01;
  static constexpr double kSleepAngularSpeed_radps = 0.01;
  static constexpr double kRestBeforeSleep_s = 0.5;

  // What the service asks of an engine.
  class Engine {
   public:
    virtual ~Engine() = default;
    // The box `id`'s collision geometry occupies now.
    virtual Eigen::AlignedBox3d bounds(std::size_t id) const = 0;
    // Whether awake body `id` touches sleeping object `other` now, or would within the coming substep (with
    // speculative contacts: after reach_bounds() for `id` in this substep).
    virtual bool reaches(std::size_t id, std::size_t other) = 0;
    // The box of everything awake body `id` may touch within the coming substep of `substep_s`: its bounds, swept by
    // its free displacement with speculative contacts.
    virtual Eigen::AlignedBox3d reach_bounds(std::size_t id, double substep_s) = 0;
    // Whether the engine's rest rule (the thresholds above) has stopped awake body `id` during the last step.
    virtual bool rested(std::size_t id) const = 0;
    // Takes body `id` out of the solver, its geometry fixed where the body rests (its pose kept for reading).
    virtual void leave_solver(std::size_t id) = 0;
    // Puts body `id` back into the solver at its resting pose, with its mass, at rest.
    virtual void enter_solver(std::size_t id) = 0;
  };

  // Every object starts fixed; the engine then adds each (add_fixed, add_awake). `cell_size_m` > 0: the grid's cell.
  // `escape_guard` (parked bodies are skipped) and `contacts` (a sleeper keeps its contacts) outlive the service.
  SleepingBodies(std::size_t object_count, double cell_size_m, const EscapeGuard& escape_guard,
                 ContactGraph& contacts);

  // A fixed object at `bounds` (its geometry never moves).
  void add_fixed(std::size_t id, const Eigen::AlignedBox3d& bounds);
  // A dynamic body, awake.
  void add_awake(std::size_t id);

  bool asleep(std::size_t id) const { return kind_[id] == Kind::asleep; }
  // The awake dynamic bodies, in the order they woke (parked ones until the step's end).
  const std::vector<std::size_t>& awake() const { return awake_; }
  // The bodies the current step simulates (awake at any time in it), ascending.
  const std::vector<std::size_t>& moved() const { return moved_; }
  // The fixed objects whose bounds overlap `box`, ascending, into `out` (cleared first).
  void fixed_near(const Eigen::AlignedBox3d& box, std::vector<std::size_t>& out) const;

  // Before a step's substeps: the bodies it moves are those awake now, and those it wakes.
  void begin_step();
  // Wakes sleeping body `id` (nothing if it is not asleep).
  void wake(std::size_t id, Engine& engine);
  // Before a substep of `substep_s`: wakes every sleeping body an awake one reaches, and those they reach in turn.
  void wake_touched(double substep_s, Engine& engine);
  // After a step: the bodies the rest rule stopped go to sleep; parked bodies leave the awake list.
  void put_rested_to_sleep(Engine& engine);

 private:
  enum class Kind : std::uint8_t { fixed, awake, asleep };

  std::vector<Kind> kind_;                          // per object
  std::vector<std::size_t> awake_;
  std::vector<std::size_t> moved_;
  std::vector<Eigen::AlignedBox3d> resting_bounds_; // per object in the grid: its geometry's box
  SpatialGrid grid_;                                // fixed geometry and sleeping bodies
  const EscapeGuard* escape_guard_;
  ContactGraph* contacts_;
  std::vector<std::size_t> wake_queue_;             // scratch
  mutable std::vector<std::int32_t> nearby_;        // scratch
};

}  // namespace impetus
