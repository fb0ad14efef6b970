// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/local_dynamics.h"

#include "haptic_controller/plane_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// Gauss–Seidel passes over the contacts: enough for a corner of three supports to settle.
constexpr int kContactPasses = 3;

// The two friction directions ODE gives a contact of normal n that names none (its dPlaneSpace), so the model's
// friction pyramid is the world's.
std::array<Eigen::Vector3d, 2> ode_tangents(const Eigen::Vector3d& n) {
  if (std::fabs(n.z()) > std::sqrt(0.5)) {
    const double k = 1.0 / std::sqrt(n.y() * n.y() + n.z() * n.z());
    const Eigen::Vector3d p(0.0, -n.z() * k, n.y() * k);
    return {p, Eigen::Vector3d((n.y() * n.y() + n.z() * n.z()) * k, -n.x() * p.z(), n.x() * p.y())};
  }
  const double k = 1.0 / std::sqrt(n.x() * n.x() + n.y() * n.y());
  const Eigen::Vector3d p(-n.y() * k, n.x() * k, 0.0);
  return {p, Eigen::Vector3d(-n.z() * p.y(), n.z() * p.x(), (n.x() * n.x() + n.y() * n.y()) * k)};
}
// Bound on drift substeps applied in one tick (a tick longer than the world's substep, e.g. after a stall).
constexpr int kMaxDriftChunksPerTick = 8;


}  // namespace

LocalBody* LocalDynamics::find_mutable(std::int32_t object_id) {
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    if (bodies_[b].object_id == object_id) return &bodies_[b];
  }
  return nullptr;
}

const LocalBody* LocalDynamics::find(std::int32_t object_id) const {
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    if (bodies_[b].object_id == object_id) return &bodies_[b];
  }
  return nullptr;
}

double LocalDynamics::yield_scale(const PlaneSet& planes, const ProxySolution& contact,
                                  const Eigen::Vector3d& force_N, double stiffness_Npm, double damping_Nspm,
                                  double dt_s) const {
  const int listed = listed_constraints(contact);
  const double force_norm_N = force_N.norm();
  if (listed <= 0 || !(dt_s > 0.0) || !(force_norm_N > 0.0) || !std::isfinite(force_norm_N)) return 1.0;
  const Eigen::Vector3d direction = force_N / force_norm_N;
  double inverse_mass_per_kg = 0.0;
  for (int j = 0; j < listed; ++j) {
    const int index = contact.active[j].plane;
    if (index < 0 || static_cast<std::uint32_t>(index) >= planes.count) continue;
    const LocalBody* body = find(planes.planes[static_cast<std::size_t>(index)].object_id);
    if (body == nullptr || !planes.planes[static_cast<std::size_t>(index)].dynamic()) continue;
    const double share = load_share(contact, j);
    // Along the force at the proxy: translation plus the turn about the CoM (r × d)ᵀ I⁻¹ (r × d), which the friction
    // anchor feels through the surface velocity (a 3 g ball pushed tangentially at its surface gives way 3.5× more
    // than pushed through its centre).
    const ContactPlane& plane = planes.planes[static_cast<std::size_t>(index)];
    const Eigen::Vector3d turning = plane.shape_traits().round ? Eigen::Vector3d(direction - direction.dot(plane.normal) * plane.normal)
                                                   : direction;  // the part of the push that turns the body
    const Eigen::Vector3d arm = (contact.proxy_m - body->com_m()).cross(turning);
    inverse_mass_per_kg += share * (body->inverse_mass_per_kg + arm.dot(body->inverse_inertia_world * arm));
  }
  const double compliance = (std::max(0.0, stiffness_Npm) * dt_s * dt_s + std::max(0.0, damping_Nspm) * dt_s) *
                            inverse_mass_per_kg;
  return std::isfinite(compliance) ? 1.0 / (1.0 + compliance) : 1.0;
}

LocalDynamics::LocalDynamics(std::uint64_t haptic_session)
    : haptic_session_(haptic_session), log_(kLoggedTicks) {}

void LocalDynamics::log_tick(double advanced_s) {
  LoggedTick& record = log_[log_next_];
  if (log_size_ == log_.size()) overwritten_tick_ = record.tick;
  record.tick = tick_;
  record.advanced_s = advanced_s;
  record.share_count = 0;
  log_next_ = (log_next_ + 1) % log_.size();
  log_size_ = std::min(log_size_ + 1, log_.size());
}

void LocalDynamics::log_share(const ImpulseShare& share) {
  if (log_size_ == 0) return;
  LoggedTick& record = log_[(log_next_ + log_.size() - 1) % log_.size()];
  if (record.tick != tick_ || record.share_count == kLoggedSharesPerTick) {
    ++unlogged_shares_;
    return;
  }
  record.shares[record.share_count++] = {share.object_id, share.impulse_Ns, share.angular_impulse_Nms};
}

std::uint64_t LocalDynamics::catch_up(std::uint64_t applied_tick) {
  if (log_size_ == 0 || log_[(log_next_ + log_.size() - 1) % log_.size()].tick <= applied_tick) return 0;
  if (overwritten_tick_ > applied_tick) {  // the ring no longer holds the first ticks to replay
    ++replay_gaps_;
    return 0;
  }
  std::uint64_t replayed = 0;
  for (std::size_t k = 0; k < log_size_; ++k) {
    const LoggedTick& record = log_[(log_next_ + log_.size() - log_size_ + k) % log_.size()];
    if (record.tick <= applied_tick) continue;
    if (record.advanced_s > 0.0) advance(record.advanced_s);
    for (std::uint32_t j = 0; j < record.share_count; ++j) {
      const LoggedShare& share = record.shares[j];
      apply_impulse(share.object_id, share.impulse_Ns, share.angular_impulse_Nms);
    }
    ++replayed;
  }
  // The replayed motion becomes the frame's: its planes move to where the bodies now are, and the bodies start again
  // from there (displacement and turn zero), so the blend and the ticks to come build on the present.
  for (std::uint32_t k = 0; k < plane_count_; ++k) {
    const int b = body_of_plane_[k];
    if (b < 0) continue;
    const LocalBody& body = bodies_[static_cast<std::size_t>(b)];
    Plane& plane = frame_.planes[k];
    plane.point_m = to_vec3(body.carry_point(to_eigen(plane.point_m)));
    plane.normal = to_vec3(body.carry_normal(to_eigen(plane.normal)));
    plane.com_m = to_vec3(body.com_m());
    if (traits(plane.shape.kind).carries_axes) {
      plane.body_axis_x = to_vec3(body.carry_axis(to_eigen(plane.body_axis_x)));
      plane.body_axis_y = to_vec3(body.carry_axis(to_eigen(plane.body_axis_y)));
    }
  }
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    LocalBody& body = bodies_[b];
    if (body.turns || body.turns_shape) body.axes = body.turn.toRotationMatrix() * body.axes;
    body.com_frame_m = body.com_m();
    body.displacement_m.setZero();
    body.turn = Eigen::Quaterniond::Identity();
  }
  return replayed;
}

void LocalDynamics::on_plane_frame(const PlaneFrame& frame, const PlaneSet* displayed,
                                   const Eigen::Vector3d& proxy_m) {
  // Which objects the finger was touching when the frame arrived: they keep the passivity hold (local_dynamics.h).
  std::array<std::int32_t, kMaxPlanes> touched_ids{};
  std::uint32_t touched_count = 0;
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    if (bodies_[b].touched) touched_ids[touched_count++] = bodies_[b].object_id;
  }
  auto was_touched = [&](std::int32_t id) {
    return std::find(touched_ids.begin(), touched_ids.begin() + touched_count, id) != touched_ids.begin() + touched_count;
  };
  // Which objects still hold a depth the replay revealed (header, "Frame boundaries"): it stays held into this frame.
  std::array<std::int32_t, kMaxPlanes> revealed_ids{};
  std::uint32_t revealed_count = 0;
  for (std::uint32_t k = 0; k < plane_count_; ++k) {
    if (blends_[k].revealed && blends_[k].normal_weight < 1.0) {
      revealed_ids[revealed_count++] = frame_.planes[k].object_id;
    }
  }
  auto was_revealed = [&](std::int32_t id) {
    return std::find(revealed_ids.begin(), revealed_ids.begin() + revealed_count, id) !=
           revealed_ids.begin() + revealed_count;
  };

  copy_used(frame, frame_);
  plane_count_ = std::min(frame.plane_count, kMaxPlanes);
  gravity_mps2_ = to_eigen(frame.gravity_mps2);
  substep_s_ = frame.world_substep_s > 0.0 && frame.world_substep_s <= frame.world_period_s ? frame.world_substep_s
                                                                                            : 0.0;
  elapsed_s_ = 0.0;
  next_drift_s_ = 0.0;
  body_count_ = 0;
  last_model_error_m_ = 0.0;
  for (std::uint32_t k = 0; k < plane_count_; ++k) {
    const Plane& plane = frame_.planes[k];
    body_of_plane_[k] = -1;
    // No response model (common/contract/frames.h): the object is immovable between world steps, rendered at the frame.
    if ((plane.flags & kPlaneDynamic) == 0 || !(plane.inverse_mass_per_kg > 0.0)) continue;
    int index = -1;
    for (std::uint32_t b = 0; b < body_count_; ++b) {
      if (bodies_[b].object_id == plane.object_id) index = static_cast<int>(b);
    }
    if (index < 0) {
      index = static_cast<int>(body_count_++);
      LocalBody& body = bodies_[static_cast<std::size_t>(index)];
      body = LocalBody{};
      body.object_id = plane.object_id;
      body.inverse_mass_per_kg = plane.inverse_mass_per_kg;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) body.inverse_inertia_world(r, c) = plane.inverse_inertia_world[3 * r + c];
      }
      // I itself, for the free rotation's angular momentum (advance); a body whose I⁻¹ is not invertible (a model
      // that leaves out some axis) keeps its ω instead.
      bool invertible = false;
      body.inverse_inertia_world.computeInverseWithCheck(body.inertia_world, invertible);
      body.precesses = invertible && body.inertia_world.allFinite();
      body.com_frame_m = to_eigen(plane.com_m);
      body.velocity_mps = to_eigen(plane.velocity_mps);
      body.angular_velocity_radps = to_eigen(plane.angular_velocity_radps);
      body.contact_count = std::min(plane.local_contact_count, kMaxLocalContacts);
      const ShapeTraits& shape = traits(plane.shape.kind);
      body.shape = plane.shape;
      body.sphere_radius_m = shape.round ? plane.shape.radius_m : 0.0;
      body.turns = shape.flat_faces;
      body.turns_shape = shape.carries_axes && !shape.flat_faces;
      body.rests_on_corners = shape.flat_faces;
      if (shape.carries_axes) {
        const Eigen::Vector3d x = to_eigen(plane.body_axis_x), y = to_eigen(plane.body_axis_y);
        body.axes << x, y, x.cross(y);
      }
      for (std::uint32_t c = 0; c < body.contact_count; ++c) {
        body.contact_normal[c] = to_eigen(plane.local_contacts[c].normal);
        body.contact_friction[c] = plane.local_contacts[c].friction;
        body.contact_holds[c] = (plane.local_contacts[c].flags & kContactHolds) != 0;
        body.neighbour_velocity_mps[c] = to_eigen(plane.local_contacts[c].other_velocity_mps);
        body.neighbour_inverse_mass_per_kg[c] = std::max(0.0, plane.local_contacts[c].other_inverse_mass_per_kg);
        body.contact_gap_m[c] = std::max(0.0, plane.local_contacts[c].gap_m);
      }
      body.touched = was_touched(plane.object_id);
    }
    body_of_plane_[k] = index;
  }

  // Over a delayed link, the pushes the world has not seen yet (header, "Delay").
  last_replayed_ticks_ = frame.report_session_applied == haptic_session_ ? catch_up(frame.report_tick_applied) : 0;

  // Blend from the plane the finger was feeling (C) to the world's (P), see the header.
  for (std::uint32_t k = 0; k < plane_count_; ++k) {
    const Plane& plane = frame_.planes[k];
    const Eigen::Vector3d point = to_eigen(plane.point_m);
    const Eigen::Vector3d normal = to_eigen(plane.normal);
    PlaneBlend& blend = blends_[k];
    blend = PlaneBlend{point, normal, 0.0, false, false, point, normal};
    const int match = displayed ? find_plane(*displayed, plane.object_id, occurrence_of(frame_, k)) : -1;
    if (match < 0) {
      // A new plane starts at the world's value, unless the replay has carried its body over the proxy (header,
      // "Delay": a round trip on, past a finger no frame had shown it near). Then the part of the proxy's depth the
      // replay made starts held and closes only as the finger withdraws (header, "Frame boundaries"), so a depth the
      // finger never pressed into is not turned into a push; the world's own part is pushed out, as without delay.
      const Plane& at_frame = frame.planes[k];
      const double frame_depth_m = to_eigen(at_frame.normal).dot(proxy_m - to_eigen(at_frame.point_m));
      const double held_m = normal.dot(proxy_m - point) - std::min(0.0, frame_depth_m);
      if (body_of_plane_[k] >= 0 && last_replayed_ticks_ > 0 && held_m < 0.0) {
        blend.from_point_m = point + held_m * normal;
        blend.last_point_m = blend.from_point_m;
        blend.hold_normal = true;
        blend.revealed = true;
      }
      continue;
    }
    const ContactPlane& before = displayed->planes[static_cast<std::size_t>(match)];
    blend.from_point_m = before.point_m;
    blend.from_normal = before.normal;
    blend.last_point_m = before.point_m;
    blend.last_normal = before.normal;
    blend.hold_normal = body_of_plane_[k] >= 0 && (before.point_m - point).dot(normal) < 0.0;
    blend.revealed = blend.hold_normal && was_revealed(plane.object_id);
    if (body_of_plane_[k] >= 0 && was_touched(plane.object_id)) {
      const double error_m = std::fabs(normal.dot(proxy_m - point) - before.normal.dot(proxy_m - before.point_m));
      last_model_error_m_ = std::max(last_model_error_m_, error_m);
    }
  }
}

void LocalDynamics::apply_drift(LocalBody& body, double h_s) const {
  Eigen::Vector3d& v = body.velocity_mps;
  v += gravity_mps2_ * h_s;
  // Unilateral supports with Coulomb friction, impulses per unit mass (see the header). A holding contact is
  // immovable; a loose one takes at most the weight it carries this substep. Taking a loose neighbour as immovable
  // would under-predict the motion: the finger would press a plane that does not yield, and the world would then
  // give the pushed body (and its neighbours) momentum nobody felt, the active error (hard case 10).
  std::array<double, kMaxLocalContacts> normal_impulse{};
  std::array<double, kMaxLocalContacts> capacity{};
  for (std::uint32_t c = 0; c < body.contact_count; ++c) {
    capacity[c] = body.contact_holds[c] ? std::numeric_limits<double>::infinity()
                                        : std::max(0.0, -gravity_mps2_.dot(body.contact_normal[c])) * h_s;
  }
  // A support the body had not reached at the frame (gap_m > 0) lets it approach by what is left of the gap within
  // this substep, and stops it there: it arrives at the substep's end, as the world's body does on its floor. What
  // is left is the gap less the centre's approach since the frame (the body's turn since then is left out: a few
  // degrees in a period move a 5 cm box's lowest corner by about a millimetre).
  std::array<double, kMaxLocalContacts> approach_mps{};
  std::array<bool, kMaxLocalContacts> reached{};
  for (std::uint32_t c = 0; c < body.contact_count; ++c) {
    const double left_m = body.contact_gap_m[c] + body.displacement_m.dot(body.contact_normal[c]);
    reached[c] = !(body.contact_gap_m[c] > 0.0) || !(left_m > 0.0);
    approach_mps[c] = reached[c] ? 0.0 : left_m / h_s;
  }
  for (int pass = 0; pass < kContactPasses; ++pass) {
    for (std::uint32_t c = 0; c < body.contact_count; ++c) {
      const double impulse = std::min(std::max(0.0, -v.dot(body.contact_normal[c]) - approach_mps[c]),
                                      capacity[c] - normal_impulse[c]);
      if (impulse > 0.0) {
        v += impulse * body.contact_normal[c];
        normal_impulse[c] += impulse;
      }
    }
  }
  if (body.rests_on_corners && body.inverse_mass_per_kg > 0.0) {
    for (std::uint32_t c = 0; c < body.contact_count; ++c) {
      if (body.contact_holds[c] && reached[c] && normal_impulse[c] > 0.0) {
        normal_impulse[c] += hold_box_corners(body, body.contact_normal[c]);
      }
    }
  }
  for (std::uint32_t c = 0; c < body.contact_count; ++c) {
    body.friction_limit[c] = 0.0;
    body.friction_used[c].setZero();
    body.corner_friction[c] = {};
    if (!(normal_impulse[c] > 0.0)) continue;
    const Eigen::Vector3d& n = body.contact_normal[c];
    const double limit = body.contact_friction[c] * normal_impulse[c];
    body.friction_limit[c] = limit;
    if (body.sphere_radius_m > 0.0 && body.inverse_mass_per_kg > 0.0) {
      // At the contact point (header): an impulse |j| against the slip lowers it by k·|j|,
      // k = 1 + m·t·((I⁻¹(c × t)) × c), the sphere's effective inverse mass along t at c (7/2 for a solid ball).
      Eigen::Vector3d& w = body.angular_velocity_radps;
      const Eigen::Vector3d lever = -body.sphere_radius_m * n;
      const Eigen::Vector3d point_velocity = v + w.cross(lever);
      const Eigen::Vector3d slip = point_velocity - point_velocity.dot(n) * n;
      const double slip_mps = slip.norm();
      if (!(slip_mps > 0.0)) continue;
      const Eigen::Vector3d t = slip / slip_mps;
      const Eigen::Matrix3d spin_per_impulse = body.inverse_inertia_world / body.inverse_mass_per_kg;  // m·I⁻¹
      const double k = 1.0 + t.dot((spin_per_impulse * lever.cross(t)).cross(lever));
      const Eigen::Vector3d j = -std::min(slip_mps / k, limit) * t;
      v += j;
      w += spin_per_impulse * lever.cross(j);
      continue;
    }
    if (body.rests_on_corners && body.inverse_mass_per_kg > 0.0) {
      apply_box_friction(body, n, limit, body.corner_friction[c]);
      continue;
    }
    const Eigen::Vector3d slip = v - v.dot(n) * n;
    const double slip_mps = slip.norm();
    if (slip_mps > 0.0) {
      const Eigen::Vector3d j = -std::min(slip_mps, limit) / slip_mps * slip;
      v += j;
      body.friction_used[c] = j;
    }
  }
  share_with_neighbours(body);
  // Rotation is otherwise left free: supports do not stop a ball rolling, and where they would stop a box tipping the model
  // over-predicts the surface's motion, the passive error. Stopping it would let the finger's friction spin a ball
  // in the world far past rolling with the finger, since the model would see its surface still.
}

std::array<Eigen::Vector3d, 4> LocalDynamics::support_corners(const LocalBody& body, const Eigen::Vector3d& n) {
  // From the body's axes as the model has turned them.
  std::array<Eigen::Vector3d, 4> corners;
  impetus::support_corners(body.shape, body.turn.toRotationMatrix() * body.axes, n, corners);
  return corners;
}

double LocalDynamics::hold_box_corners(LocalBody& body, const Eigen::Vector3d& n) {
  const std::array<Eigen::Vector3d, 4> corners = support_corners(body, n);
  const Eigen::Matrix3d spin_per_impulse = body.inverse_inertia_world / body.inverse_mass_per_kg;  // m·I⁻¹
  Eigen::Vector3d& v = body.velocity_mps;
  Eigen::Vector3d& w = body.angular_velocity_radps;
  constexpr std::array<int, 4> kOrder{0, 3, 1, 2};
  std::array<double, 4> accumulated{};
  for (int pass = 0; pass < kContactPasses; ++pass) {
    for (int i = 0; i < 4; ++i) {
      const auto c = static_cast<std::size_t>(kOrder[static_cast<std::size_t>(pass % 2 == 0 ? i : 3 - i)]);
      const Eigen::Vector3d& r = corners[c];
      const double closing_mps = (v + w.cross(r)).dot(n);
      const Eigen::Vector3d lever = r.cross(n);
      const double k = 1.0 + lever.dot(spin_per_impulse * lever);  // the corner's inverse mass along n, per unit mass
      const double total = std::max(0.0, accumulated[c] - closing_mps / k);
      const double p = total - accumulated[c];
      accumulated[c] = total;
      v += p * n;
      w += spin_per_impulse * (p * lever);
    }
  }
  return accumulated[0] + accumulated[1] + accumulated[2] + accumulated[3];
}

void LocalDynamics::apply_box_friction(LocalBody& body, const Eigen::Vector3d& n, double limit,
                                       std::array<std::array<double, 2>, 4>& accumulated) {
  const std::array<Eigen::Vector3d, 4> corners = support_corners(body, n);
  // Spin about n per unit of angular impulse about n, per unit mass: m·(n·I⁻¹·n).
  const double spin_per_impulse = n.dot(body.inverse_inertia_world * n) / body.inverse_mass_per_kg;
  // The world's friction is a pyramid (ODE's dContactApprox1): each of two tangent directions bounded by the corner's
  // share of μ·P on its own, the directions ODE picks for a contact without its own (dPlaneSpace of n).
  const std::array<Eigen::Vector3d, 2> tangents = ode_tangents(n);
  Eigen::Vector3d& v = body.velocity_mps;
  Eigen::Vector3d& w = body.angular_velocity_radps;
  // Sequential impulses, each corner's accumulated impulse per direction kept within its share of the limit; the
  // corners in diagonal pairs and the order reversed on alternate passes, so a box that only slides gets no spin from
  // the order.
  constexpr std::array<int, 4> kOrder{0, 3, 1, 2};
  const double corner_limit = 0.25 * limit;
  for (int pass = 0; pass < kContactPasses; ++pass) {
    for (int i = 0; i < 4; ++i) {
      const auto c = static_cast<std::size_t>(kOrder[static_cast<std::size_t>(pass % 2 == 0 ? i : 3 - i)]);
      const Eigen::Vector3d& r = corners[c];
      for (std::size_t d = 0; d < 2; ++d) {
        const Eigen::Vector3d& t = tangents[d];
        const double slip_mps = (v + w.cross(r)).dot(t);
        const double lever = n.dot(r.cross(t));
        const double k = 1.0 + spin_per_impulse * lever * lever;  // the corner's inverse mass along t, per unit mass
        const double total = std::clamp(accumulated[c][d] - slip_mps / k, -corner_limit, corner_limit);
        const double j = total - accumulated[c][d];
        accumulated[c][d] = total;
        v += j * t;
        w += spin_per_impulse * lever * j * n;
      }
    }
  }
}

void LocalDynamics::hold_after_push(LocalBody& body) {
  if (!(body.inverse_mass_per_kg > 0.0) || body.sphere_radius_m > 0.0) return;
  Eigen::Vector3d& v = body.velocity_mps;
  for (std::uint32_t c = 0; c < body.contact_count; ++c) {
    const double limit = body.friction_limit[c];
    if (!(limit > 0.0)) continue;
    const Eigen::Vector3d& n = body.contact_normal[c];
    if (body.rests_on_corners) {
      apply_box_friction(body, n, limit, body.corner_friction[c]);
      continue;
    }
    const Eigen::Vector3d slip = v - v.dot(n) * n;
    const double slip_mps = slip.norm();
    const double left = limit - body.friction_used[c].norm();
    if (!(slip_mps > 0.0) || !(left > 0.0)) continue;
    const Eigen::Vector3d j = -std::min(slip_mps, left) / slip_mps * slip;
    v += j;
    body.friction_used[c] += j;
  }
}

void LocalDynamics::share_with_neighbours(LocalBody& body) {
  if (!(body.inverse_mass_per_kg > 0.0)) return;
  for (std::uint32_t c = 0; c < body.contact_count; ++c) {
    const double neighbour_inverse_mass = body.neighbour_inverse_mass_per_kg[c];
    if (body.contact_holds[c] || !(neighbour_inverse_mass > 0.0)) continue;
    const Eigen::Vector3d& n = body.contact_normal[c];
    Eigen::Vector3d& neighbour_velocity = body.neighbour_velocity_mps[c];
    const double approach_mps = (body.velocity_mps - neighbour_velocity).dot(n);
    if (!(approach_mps < 0.0)) continue;
    const double impulse_Ns = -approach_mps / (body.inverse_mass_per_kg + neighbour_inverse_mass);
    body.velocity_mps += body.inverse_mass_per_kg * impulse_Ns * n;
    neighbour_velocity -= neighbour_inverse_mass * impulse_Ns * n;
  }
}

void LocalDynamics::advance(double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  // Drift on the world's substep grid: ODE's substep k changes v at time k·h (its x then integrates the new v), so
  // the drift of substep k is applied by the first tick that starts at or after k·h. Half a tick of slack absorbs
  // rounding in elapsed time.
  const double h_s = substep_s_ > 0.0 ? substep_s_ : dt_s;
  int chunks = 0;
  while (elapsed_s_ + 0.5 * dt_s > next_drift_s_ && chunks < kMaxDriftChunksPerTick) {
    for (std::uint32_t b = 0; b < body_count_; ++b) apply_drift(bodies_[b], h_s);
    next_drift_s_ += h_s;
    ++chunks;
  }
  if (chunks == kMaxDriftChunksPerTick) next_drift_s_ = elapsed_s_ + h_s;  // a long gap: do not replay it
  elapsed_s_ += dt_s;
  // Curved planes are carried by the CoM's displacement only, flat faces also turned (local_dynamics.h); ω also gives
  // the surface velocity that friction sees, and is reconciled by the next frame.
  for (std::uint32_t b = 0; b < body_count_; ++b) {
    LocalBody& body = bodies_[b];
    body.displacement_m += body.velocity_mps * dt_s;
    const double angle = body.angular_velocity_radps.norm() * dt_s;
    if ((body.turns || body.turns_shape) && angle > 0.0 && std::isfinite(angle)) {
      const Eigen::Quaterniond step(Eigen::AngleAxisd(angle, body.angular_velocity_radps.normalized()));
      body.turn = (step * body.turn).normalized();
      // Free rotation keeps the angular momentum L = I·ω, not ω: the inertia turns with the body (I ← R·I·Rᵀ) and
      // ω = I⁻¹·L follows, the torque-free precession both engines integrate. A 3 × 2 × 1.2 cm box spun off its
      // principal axes at 2.7 rad/s turns 0.01 rad away from a constant ω in a 10 Hz period (0.15 mm at its corners).
      if (body.precesses) {
        const Eigen::Matrix3d rotation = step.toRotationMatrix();
        const Eigen::Vector3d momentum = body.inertia_world * body.angular_velocity_radps;
        body.inertia_world = rotation * body.inertia_world * rotation.transpose();
        body.inverse_inertia_world = rotation * body.inverse_inertia_world * rotation.transpose();
        body.angular_velocity_radps = body.inverse_inertia_world * momentum;
      }
    }
  }
}

void LocalDynamics::apply_impulse(std::int32_t object_id, const Eigen::Vector3d& impulse_Ns,
                                  const Eigen::Vector3d& angular_impulse_Nms) {
  LocalBody* body = find_mutable(object_id);
  if (!body || !impulse_Ns.allFinite() || !angular_impulse_Nms.allFinite()) return;
  // Paper §3.5 at the haptic rate: Δv = J/m, Δω = I⁻¹·L.
  body->velocity_mps += body->inverse_mass_per_kg * impulse_Ns;
  body->angular_velocity_radps += body->inverse_inertia_world * angular_impulse_Nms;
  hold_after_push(*body);
  share_with_neighbours(*body);
  body->pushed_Ns += impulse_Ns;
  body->touched = true;
}

void LocalDynamics::render(double w, const Eigen::Vector3d& proxy_m, PlaneSet& out) {
  w = std::isfinite(w) ? std::clamp(w, 0.0, 1.0) : 1.0;
  out.count = plane_count_;
  for (std::uint32_t k = 0; k < plane_count_; ++k) {
    const Plane& now = frame_.planes[k];
    ContactPlane& plane = out.planes[k];
    plane = to_contact_plane(now);
    PlaneBlend& blend = blends_[k];
    const int b = body_of_plane_[k];
    LocalBody* body = b >= 0 ? &bodies_[static_cast<std::size_t>(b)] : nullptr;

    const Eigen::Vector3d target_point = to_eigen(now.point_m);
    const Eigen::Vector3d target_normal = to_eigen(now.normal);
    Eigen::Vector3d point = target_point;
    Eigen::Vector3d normal = target_normal;
    if (normals_flip(blend.from_normal, target_normal)) {
      if (!flip_switched(w)) {  // §3.2's flip rule (plane_matching.h)
        point = blend.from_point_m;
        normal = blend.from_normal;
      }
    } else {
      const Eigen::Vector3d offset = blend.from_point_m - target_point;
      const double offset_normal_m = offset.dot(target_normal);
      const Eigen::Vector3d tangential = (1.0 - w) * (offset - offset_normal_m * target_normal);
      double normal_weight = std::max(blend.normal_weight, w);
      if (blend.hold_normal && body) {
        // Passivity: the gap toward the finger (offset_normal_m < 0) closes no further than the last proxy, so the
        // blend never pushes the finger out. Signed distance of the proxy to the plane as a function of w_n:
        //     d(w_n) = d_P + (1 − w_n)·|offset_normal|,   d_P = its distance to the plane with the gap closed.
        // A revealed depth closes by no more than the finger's clearance from last tick's plane (header): not into
        // room the body made.
        const double gap_m = -offset_normal_m;
        const double d_closed_m =
            body->carry_normal(target_normal).dot(proxy_m - body->carry_point(target_point + tangential));
        if (d_closed_m < 0.0) {
          double limit = 1.0 + d_closed_m / gap_m;
          if (blend.revealed) {
            const double clearance_m = std::max(0.0, blend.last_normal.dot(proxy_m - blend.last_point_m));
            limit = std::min(limit, blend.normal_weight + clearance_m / gap_m);
          }
          normal_weight = std::min(normal_weight, std::max(blend.normal_weight, limit));
        }
      }
      blend.normal_weight = normal_weight;
      point = target_point + tangential + (1.0 - normal_weight) * offset_normal_m * target_normal;
      const Eigen::Vector3d blended = (1.0 - w) * blend.from_normal + w * target_normal;
      normal = blended / blended.norm();  // ≥ 1/√2 for unit normals with dot ≥ 0
    }

    if (body) {
      plane.point_m = body->carry_point(point);
      plane.normal = body->carry_normal(normal);  // turned for a flat face only: see the header
      blend.last_point_m = plane.point_m;
      blend.last_normal = plane.normal;
      plane.com_m = body->com_m();
      // A shape travels with its plane: its centre is the CoM, its axes turn with the body (shape_planes.h).
      for (int axis = 0; axis < 3; ++axis) plane.axes.col(axis) = body->carry_axis(plane.axes.col(axis));
      plane.velocity_mps = body->velocity_mps;
      plane.angular_velocity_radps = body->angular_velocity_radps;
    } else {
      plane.point_m = point;
      plane.normal = normal;
    }
  }
  for (std::uint32_t b = 0; b < body_count_; ++b) bodies_[b].touched = false;
}

}  // namespace impetus
