// SPDX-License-Identifier: Apache-2.0
#pragma once
// Local coupling, the world's side (paper §6.3): the haptic side moves the touched objects between world frames
// (haptic_controller/local_dynamics.h), so the world must apply each impulse when it was rendered, not all at the
// start of the step, and tell the haptic side what each object touches (its frames' LocalContacts).
//
// The haptic side moved the object tick by tick: an impulse J_k rendered at haptic time t_k has displaced it by
// J_k·(t_end − t_k)/m by the end of the window. The engine's semi-implicit Euler step gives a force held during
// substep s (length h) exactly the effect of an impulse at time s·h (v changes at the end of the substep, x then
// integrates the new v), so the world reproduces both the momentum Σ J_k and the displacement Σ J_k·(t_end − t_k)/m by
// giving each axis's impulse the centroid time
//     c = (Σ J_k·t_k − t_start·Σ J_k) / Σ J_k      (from the report's first moments, contract/frames.h)
// spread over the substeps as a ramp with that centroid (substep_spread.h): any non-negative spread with centroid c
// has the same end state for a free body, and a spread one lets contact friction meet a steady push as the force it
// was (a push concentrated in one substep meets that substep's friction budget only, and a resting object creeps).
// Slot `substeps` is the end of the window (an impulse in the very last tick); a body touching something is spread
// over the substeps only (c clamped to the last one). The world's next state then agrees with what the finger felt
// exactly for a free body (up to h·J/m for an impulse at the very end); with contacts, up to how friction sees the
// spread (it only acts while the object slides; the contact itself is blended, local_dynamics.h).
//
// Limit: with one haptic tick per world step (a world as fast as the haptic loop) the centroid is that tick's instant,
// the window's end, and the impulse goes into one substep; a steady push then meets one substep's friction budget.

#include "world_manager/couplings/coupling.h"

#include <vector>

namespace impetus {

class LocalCoupling final : public CouplingStrategy {
 public:
  explicit LocalCoupling(const CouplingContext& context);

  Coupling kind() const override { return Coupling::local; }
  void take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment, bool moment_finite,
                    const RenderWindow& window) override;
  void before_substep(int substep) override { apply_slot(substep); }
  void after_step() override { apply_slot(context_.substeps); }
  bool needs_contacts() const override { return true; }
  // Each dynamic object's plane carries the contacts the object had in the last substep, the constraints of the
  // haptic side's local model; and what it would land on, gap_m below it, if it rests on nothing yet (support_ahead).
  void annotate(PlaneFrame& frame) override;

 private:
  // The level face a static box turns up (a table's top): the plane through `centre_m` with normal `normal`, bounded
  // by ±half_u_m along axis_u and ±half_v_m along axis_v.
  struct TopFace {
    std::size_t object;
    Eigen::Vector3d centre_m, normal, axis_u, axis_v;
    double half_u_m, half_v_m;
  };
  // What object `id` would land on if it fell, when it rests on nothing: the nearest below it of the floor and the
  // top faces of static boxes whose whole face lies under the body's bounds. The model must stop the body where the
  // world will, not a round trip after the world's body landed (a body set down by fingers over a delayed link, whose
  // model still held it in the air, was lifted off the floor by them and thrown). Appended to `plane`'s contacts when
  // there is room and no contact already pushes up.
  void support_ahead(std::size_t id, Plane& plane) const;
  void schedule(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment, const RenderWindow& window);
  void apply_slot(int slot);

  // Per object, the impulse and angular impulse to apply in each substep of this step (slot `substeps`: after the
  // last substep, a pure velocity change); sized when the object is first pushed.
  std::vector<std::vector<Eigen::Vector3d>> impulse_Ns_;
  std::vector<std::vector<Eigen::Vector3d>> angular_Nms_;
  // The objects with impulse scheduled in this step: a step costs the objects pushed, not the objects that exist.
  std::vector<std::size_t> scheduled_;
  std::vector<bool> is_scheduled_;
  std::vector<TopFace> top_faces_;  // of the scene's static boxes, taken once
};

}  // namespace impetus
