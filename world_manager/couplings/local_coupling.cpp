// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/local_coupling.h"

#include "common/shape/shape.h"
#include "world_manager/couplings/substep_spread.h"
#include "world_manager/features/contact_graph.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace impetus {

LocalCoupling::LocalCoupling(const CouplingContext& context)
    : CouplingStrategy(context),
      impulse_Ns_(context.scene.objects.size()),
      angular_Nms_(context.scene.objects.size()),
      is_scheduled_(context.scene.objects.size(), false) {
  for (std::size_t id = 0; id < context.scene.objects.size(); ++id) {
    const SceneObject& box = context.scene.objects[id];
    if (box.dynamic || box.deformable || box.shape.kind != ShapeKind::box) continue;
    // Where the scene puts it: a static body does not move (the world's states are not filled yet here).
    const Eigen::Vector3d centre_m = to_eigen(box.position_m);
    const Eigen::Matrix3d axes = Eigen::Quaterniond(box.orientation_wxyz[0], box.orientation_wxyz[1],
                                                    box.orientation_wxyz[2], box.orientation_wxyz[3])
                                     .normalized()
                                     .toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
      for (const double sign : {1.0, -1.0}) {
        const Eigen::Vector3d normal = sign * axes.col(i);
        // Level to the contact graph's own tolerance: a face tilted more is a slope, met only as a contact.
        if (!(normal.z() > ContactGraph::kSameContactCosine)) continue;
        const int u = (i + 1) % 3, v = (i + 2) % 3;
        top_faces_.push_back({id, centre_m + normal * (0.5 * box.shape.box_size_m[i]), normal, axes.col(u),
                              axes.col(v), 0.5 * box.shape.box_size_m[u], 0.5 * box.shape.box_size_m[v]});
      }
    }
  }
}

void LocalCoupling::take_impulse(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment,
                                 bool moment_finite, const RenderWindow& window) {
  if (moment_finite) {
    schedule(id, delta, moment, window);
  } else {
    apply_velocity_change(id, delta.impulse_Ns, delta.angular_impulse_Nms);  // cannot place it in time
  }
}

void LocalCoupling::schedule(std::size_t id, const ImpulseDelta& delta, const ImpulseDelta& moment,
                             const RenderWindow& window) {
  const int substeps = context_.substeps;
  const double period_s = context_.world_period_s;
  const double h = period_s / substeps;
  const double scale = period_s / window.length_s;  // lockstep: 1; real time: the window mapped onto this step
  // A body touching something gets its impulse within the substeps, where its contacts see it (apply_slot); a free
  // body may also take some at the window's end, as a velocity change after the last substep.
  const bool touching = context_.engine.contacts().touching(static_cast<std::int32_t>(id));
  const int slot_count = touching ? substeps : substeps + 1;
  // What friction can hold in one substep: μ·N·h. A push friction could hold over the time it lasted goes in evenly,
  // its moment of force too: the ramp's centroid may lie near the step's end (one haptic tick per world step: a 1 kHz
  // world), and there it puts most of the push in one substep, beyond what friction holds there, and most of its
  // torque, which rocks a box off an edge; a resting object then creeps under a push it should resist. The push's
  // timing shifts by up to one step, which an object friction holds does not show. A push friction cannot hold keeps
  // its exact timing: the object slides anyway.
  // How long it lasted: each tick's impulse is a force over the tick before its time, so the force's centroid along
  // the push is half a tick before the impulses' one, and a non-negative force with that centroid spans at most the
  // slots a ramp about it covers (spread_length). A sharp push at a window's end (a tap's first ticks at a 10 Hz
  // world) spans a substep or two, not the step: spread evenly, friction would swallow it.
  const double holdable_per_slot_Ns =
      touching ? context_.engine.contacts().friction_capacity_N(static_cast<std::int32_t>(id)) * h : 0.0;
  bool even = false;
  if (touching && delta.impulse_Ns.norm() <= holdable_per_slot_Ns * slot_count) {
    const double squared_Ns2 = delta.impulse_Ns.squaredNorm();
    const double moment_about_start_Nss =
        (moment.impulse_Ns - window.start_s * delta.impulse_Ns).dot(delta.impulse_Ns) * scale;
    const double force_centroid_s =
        squared_Ns2 > 0.0 ? moment_about_start_Nss / squared_Ns2 - 0.5 * window.tick_s * scale : 0.5 * period_s;
    const int lasted_slots = std::isfinite(force_centroid_s) ? spread_length(force_centroid_s / h, slot_count)
                                                             : slot_count;
    even = delta.impulse_Ns.norm() <= holdable_per_slot_Ns * lasted_slots;
  }
  auto place = [&](double amount, double first_moment, int axis, std::vector<Eigen::Vector3d>& slots) {
    // Moment about the window's start, mapped onto this step: Σ J_k·c_k with c_k ∈ [0, T_w].
    const double moment_about_start = (first_moment - window.start_s * amount) * scale;
    if (!std::isfinite(moment_about_start)) {  // cannot place it: all of it after the last substep (velocity only)
      slots[static_cast<std::size_t>(substeps)][axis] += amount;
      return;
    }
    const double c = amount != 0.0 ? moment_about_start / amount : -1.0;
    if (even) {
      for (int slot = 0; slot < slot_count; ++slot) slots[static_cast<std::size_t>(slot)][axis] += amount / slot_count;
    } else if (c >= 0.0 && c <= period_s) {
      spread_over_slots(c / h, slot_count,
                        [&](int slot, double weight) { slots[static_cast<std::size_t>(slot)][axis] += weight * amount; });
    } else if (amount != 0.0 || moment_about_start != 0.0) {
      // The impulse changed sign within the window (its centroid lies outside it, or it summed to zero): split it
      // between the window's ends, b at T_w and a = J − b at 0, with b·T_w = Σ J_k·c_k: still exact in momentum and
      // in displacement for a free body.
      const double at_end = moment_about_start / period_s;
      slots[0][axis] += amount - at_end;
      slots[static_cast<std::size_t>(substeps)][axis] += at_end;
    }
  };
  if (!is_scheduled_[id]) {
    const std::size_t slots = static_cast<std::size_t>(substeps) + 1;
    if (impulse_Ns_[id].size() != slots) {
      impulse_Ns_[id].assign(slots, Eigen::Vector3d::Zero());
      angular_Nms_[id].assign(slots, Eigen::Vector3d::Zero());
    }
    is_scheduled_[id] = true;
    scheduled_.push_back(id);
  }
  for (int axis = 0; axis < 3; ++axis) {
    place(delta.impulse_Ns[axis], moment.impulse_Ns[axis], axis, impulse_Ns_[id]);
    place(delta.angular_impulse_Nms[axis], moment.angular_impulse_Nms[axis], axis, angular_Nms_[id]);
  }
  context_.engine.wake(id);
  context_.applied.add(id, delta.impulse_Ns, delta.angular_impulse_Nms);
}

void LocalCoupling::apply_slot(int slot) {
  // Substep slots: the scheduled impulse as a force held for one substep (the engine clears forces after each).
  // Slot `substeps` (an impulse at the very end of the window): for a free body, a velocity change after the last
  // substep (exact: no displacement). For a body that touched something at the last frame it goes into the last
  // substep instead, where the contacts see it: as a bare velocity change it would skip them for a whole step (a
  // light ball pushed into the floor in the last tick would sink into it before the engine pushed it back out). The
  // price there is h·J/m of displacement, blended in at the next frame (local_dynamics.h).
  const int substeps = context_.substeps;
  const double h = context_.world_period_s / substeps;
  const ContactGraph& contacts = context_.engine.contacts();  // still the last step's: recorded after this hook
  for (const std::size_t id : scheduled_) {
    Eigen::Vector3d& impulse_Ns = impulse_Ns_[id][static_cast<std::size_t>(slot)];
    Eigen::Vector3d& angular_Nms = angular_Nms_[id][static_cast<std::size_t>(slot)];
    if (slot + 1 == substeps && contacts.touching(static_cast<std::int32_t>(id))) {
      Eigen::Vector3d& end_Ns = impulse_Ns_[id][static_cast<std::size_t>(substeps)];
      Eigen::Vector3d& end_Nms = angular_Nms_[id][static_cast<std::size_t>(substeps)];
      impulse_Ns += end_Ns;
      angular_Nms += end_Nms;
      end_Ns.setZero();
      end_Nms.setZero();
    }
    if (impulse_Ns.isZero(0.0) && angular_Nms.isZero(0.0)) continue;
    if (slot < substeps) {
      push_force(id, impulse_Ns / h, angular_Nms / h);
    } else {
      Eigen::Vector3d velocity_mps;
      Eigen::Vector3d angular_radps;
      context_.engine.velocity(id, velocity_mps, angular_radps);
      const ObjectState& state = context_.states[id];
      const double admitted = context_.port.admit_velocity_change(id, impulse_Ns, angular_Nms, velocity_mps,
                                                                  angular_radps, state.inverse_mass_per_kg,
                                                                  state.inverse_inertia_world);
      const Eigen::Vector3d new_velocity_mps = velocity_mps + state.inverse_mass_per_kg * admitted * impulse_Ns;
      const Eigen::Vector3d new_angular_radps = angular_radps + state.inverse_inertia_world * admitted * angular_Nms;
      context_.engine.set_velocity(id, new_velocity_mps, new_angular_radps);
      context_.port.record_velocity_change(id, admitted * impulse_Ns, admitted * angular_Nms, velocity_mps,
                                           angular_radps, new_velocity_mps, new_angular_radps);
    }
    impulse_Ns.setZero();
    angular_Nms.setZero();
  }
  if (slot == substeps) {  // every slot is applied and zero again
    for (const std::size_t id : scheduled_) is_scheduled_[id] = false;
    scheduled_.clear();
  }
}

void LocalCoupling::annotate(PlaneFrame& frame) {
  ContactGraph& contacts = context_.engine.contacts();
  for (std::uint32_t k = 0; k < frame.plane_count; ++k) {
    Plane& plane = frame.planes[k];
    plane.local_contact_count = 0;
    if ((plane.flags & kPlaneDynamic) == 0 || plane.object_id < 0) continue;
    plane.local_contact_count = contacts.local_contacts(plane.object_id, context_.states, plane.local_contacts);
    if (static_cast<std::size_t>(plane.object_id) < context_.states.size()) {
      support_ahead(static_cast<std::size_t>(plane.object_id), plane);
    }
  }
}

void LocalCoupling::support_ahead(std::size_t id, Plane& plane) const {
  if (plane.local_contact_count >= kMaxLocalContacts) return;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // the floor is the plane z = height_m, solid below
  // A contact the world saw that pushes the body up (the floor, a table, a body it rests on) already stops it.
  for (std::uint32_t c = 0; c < plane.local_contact_count; ++c) {
    if (to_eigen(plane.local_contacts[c].normal).dot(up) > ContactGraph::kSameContactCosine) return;
  }
  const SceneObject& object = context_.scene.objects[id];
  const BodyPose& pose = context_.states[id].pose;
  // How far the body is above a level plane through `point_m` with normal `normal`: its centre's height less the
  // support function toward the plane (common/shape/shape.h), exact for every kind; a mesh's from its vertices.
  const auto height_above = [&](const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal) {
    return normal.dot(pose.position_m - point_m) - support_m(object.shape, pose.orientation.conjugate() * (-normal));
  };
  double best_gap_m = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_normal = up;
  double best_friction = 0.0;
  const Floor& floor = context_.scene.floor;
  if (floor.present) {
    best_gap_m = height_above(Eigen::Vector3d(0.0, 0.0, floor.height_m), up);
    best_friction = combine_friction(object.material.dynamic_friction, floor.material.dynamic_friction);
  }
  // A top face holds the body only where the face is: every corner of the body's bounds must lie over it (a body
  // partly over the edge may tip off in the world, and a model that held it would push back what the world lets go).
  const Eigen::AlignedBox3d bounds = world_bounds(object.shape, pose);
  for (const TopFace& face : top_faces_) {
    bool over = true;
    for (int k = 0; k < 8 && over; ++k) {
      const Eigen::Vector3d offset = bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)) - face.centre_m;
      over = std::abs(offset.dot(face.axis_u)) <= face.half_u_m && std::abs(offset.dot(face.axis_v)) <= face.half_v_m;
    }
    if (!over) continue;
    const double gap_m = height_above(face.centre_m, face.normal);
    // Below the face's plane the body is beside or under the box, not on it (kOnSurface_m: rounding).
    if (gap_m < -kOnSurface_m || !(gap_m < best_gap_m)) continue;
    best_gap_m = gap_m;
    best_normal = face.normal;
    best_friction = combine_friction(object.material.dynamic_friction,
                                     context_.scene.objects[face.object].material.dynamic_friction);
  }
  if (!std::isfinite(best_gap_m)) return;
  LocalContact& contact = plane.local_contacts[plane.local_contact_count++];
  contact = LocalContact{};
  contact.normal = to_vec3(best_normal);
  contact.friction = best_friction;
  contact.flags = kContactHolds;
  contact.gap_m = std::max(0.0, best_gap_m);
}

}  // namespace impetus
