// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/impulse_accumulator.h"

#include "haptic_controller/gram_solve.h"

#include <algorithm>
#include <cmath>

namespace impetus {
namespace {

// √3 plus rounding: the largest Σ|c_k|/|J| of a split over pairwise perpendicular normals (split_by_normals).
constexpr double kMaxSplitRatio = 1.7320508075688772 * (1.0 + 1e-9);

void add_to(Vec3& total, const Eigen::Vector3d& delta) {
  for (int a = 0; a < 3; ++a) total[a] += delta[a];
}

// The reaction's part along each listed plane's normal (see add()).
std::array<Eigen::Vector3d, kMaxActiveConstraints + 1> split_by_normals(const PlaneSet& planes,
                                                                         const ProxySolution& contact,
                                                                         const Eigen::Vector3d& reaction_Ns) {
  std::array<Eigen::Vector3d, kMaxActiveConstraints + 1> parts{};
  for (Eigen::Vector3d& part : parts) part.setZero();
  // The normal components, over the independent active planes (a pinch's conflicting plane, listed last, depends on
  // them and takes no normal part), by least squares with c_k ≥ 0: a plane pushes, it never pulls.
  const int independent = std::min(contact.active_count - (contact.infeasible ? 1 : 0), kMaxActiveConstraints);
  std::array<bool, kMaxActiveConstraints> used{};
  for (int j = 0; j < independent; ++j) used[static_cast<std::size_t>(j)] = true;
  for (int round = 0; round < kMaxActiveConstraints; ++round) {
    Eigen::Matrix3d normals = Eigen::Matrix3d::Zero();
    std::array<int, kMaxActiveConstraints> column_of{};
    int columns = 0;
    for (int j = 0; j < independent; ++j) {
      if (!used[static_cast<std::size_t>(j)]) continue;
      column_of[static_cast<std::size_t>(columns)] = j;
      normals.col(columns++) = planes.planes[static_cast<std::size_t>(contact.active[j].plane)].normal;
    }
    for (Eigen::Vector3d& part : parts) part.setZero();
    if (columns == 0) break;
    const Eigen::Vector3d c = gram_solve(normals, columns, normals.transpose() * reaction_Ns);
    // The reaction pushes object k along −n_k: c_k ≤ 0 is a push, c_k > 0 would be a pull.
    bool all_push = true;
    for (int q = 0; q < columns; ++q) {
      if (c[q] > 0.0 || !std::isfinite(c[q])) {
        used[static_cast<std::size_t>(column_of[static_cast<std::size_t>(q)])] = false;
        all_push = false;
      }
    }
    if (!all_push) continue;
    // Normals at most 90° apart (a box's corner, a wall on the floor) split any reaction with Σ|c_k| ≤ √3·|J|. More
    // than that means planes facing each other, and the excess is a squeeze: pushes that cancel on the finger and
    // only drive the objects apart, by an amount the ill-conditioned split makes up (two nearly opposed balls' planes
    // gave 0.06 N·s each for a 3 mN·s reaction). No split then: the multipliers share the reaction as it is.
    double total = 0.0;
    for (int q = 0; q < columns; ++q) total -= c[q];
    if (!(total <= kMaxSplitRatio * reaction_Ns.norm())) {
      for (Eigen::Vector3d& part : parts) part.setZero();
      break;
    }
    for (int q = 0; q < columns; ++q) {
      parts[static_cast<std::size_t>(column_of[static_cast<std::size_t>(q)])] = c[q] * normals.col(q);
    }
    break;
  }
  return parts;
}

}  // namespace


ImpulseAccumulator::ImpulseAccumulator(std::uint64_t haptic_session, EndpointId endpoint) {
  report_.haptic_session = haptic_session;
  report_.endpoint = endpoint;
}

void ImpulseAccumulator::on_plane_frame(const PlaneFrame& frame) {
  if (frame.world_session != report_.world_session) {
    // A new world: what the last one did not apply is abandoned, and the totals count against this one from zero.
    for (std::uint32_t e = 0; e < report_.entry_count; ++e) {
      for (int a = 0; a < 3; ++a) abandoned_Ns_[a] += report_.entries[e].impulse_Ns[a];
      report_.entries[e] = ObjectImpulse{};
    }
    for (int a = 0; a < 3; ++a) abandoned_Ns_[a] += report_.static_impulse_Ns[a];
    report_.entry_count = 0;
    report_.static_impulse_Ns = {};
    report_.world_session = frame.world_session;

  }
  applied_this_session_ = frame.report_session_applied == report_.haptic_session;
  applied_tick_ = applied_this_session_ ? frame.report_tick_applied : 0;
}

ObjectImpulse* ImpulseAccumulator::entry_for(std::int32_t object_id) {
  for (std::uint32_t e = 0; e < report_.entry_count; ++e) {
    if (report_.entries[e].object_id == object_id) return &report_.entries[e];
  }
  ObjectImpulse* slot = nullptr;
  if (report_.entry_count < kMaxImpulseEntries) {
    slot = &report_.entries[report_.entry_count++];
  } else if (applied_this_session_) {
    // Reuse the oldest entry the world has applied in full.
    for (std::uint32_t e = 0; e < report_.entry_count; ++e) {
      ObjectImpulse& candidate = report_.entries[e];
      if (candidate.last_tick <= applied_tick_ && (!slot || candidate.last_tick < slot->last_tick)) slot = &candidate;
    }
    if (slot) evicted_Ns_ += to_eigen(slot->impulse_Ns);
  }
  if (!slot) return nullptr;
  *slot = ObjectImpulse{};
  slot->object_id = object_id;
  slot->epoch = ++epoch_counter_;
  return slot;
}


void ImpulseAccumulator::add(const PlaneSet& planes, const ProxySolution& contact,
                             const Eigen::Vector3d& force_on_finger_N, double dt_s, std::uint64_t tick) {
  const Eigen::Vector3d reaction_Ns = -force_on_finger_N * dt_s;  // paper §3.4: the user's push on the world
  total_Ns_ += reaction_Ns;
  // The hand's input (header): this tick's force, J_k/Δt_k per object, against the finger's displacement over the
  // tick that led to it, Δx_k (the rectangle rule of a time-domain passivity observer, f_k·v_k·Δt), where positive.
  // Known now, so the world's budget holds this tick's push as soon as the push itself. Only from the tick just
  // before: across a gap (no finger, a stalled servo) there is no displacement to pair.
  const Eigen::Vector3d finger_m = to_eigen(report_.finger_m);
  const bool paired = tick == hand_tick_ + 1 && dt_s > 0.0 && finger_m.allFinite() && hand_finger_m_.allFinite();
  const Eigen::Vector3d finger_velocity_mps =
      paired ? Eigen::Vector3d((finger_m - hand_finger_m_) / dt_s) : Eigen::Vector3d::Zero();
  hand_tick_ = tick;
  hand_finger_m_ = finger_m;
  last_share_count_ = 0;
  if (reaction_Ns.isZero(0.0)) return;  // nothing to share (and no multiplier is trusted when the force was zeroed)

  const int listed = listed_constraints(contact);
  if (listed <= 0) {
    dropped_Ns_ += reaction_Ns;
    ++dropped_shares_;
    return;
  }
  // Each object is pushed along its own normal by its part of the reaction; what lies in no normal (friction along
  // the surface) is shared by the multipliers (header).
  const std::array<Eigen::Vector3d, kMaxActiveConstraints + 1> normal_parts =
      split_by_normals(planes, contact, reaction_Ns);
  Eigen::Vector3d remainder_Ns = reaction_Ns;
  for (int j = 0; j < listed; ++j) remainder_Ns -= normal_parts[static_cast<std::size_t>(j)];
  for (int j = 0; j < listed; ++j) {
    const Eigen::Vector3d impulse_Ns = normal_parts[static_cast<std::size_t>(j)] + load_share(contact, j) * remainder_Ns;
    const ContactPlane& plane = planes.planes[contact.active[j].plane];
    const Eigen::Vector3d angular_Nms = plane.angular_impulse_Nms(contact.proxy_m, impulse_Ns);
    // Where the surface was pressed (frames.h ObjectImpulse::press_*): the push into it at the proxy beyond
    // what the surface holds without yielding (a deformable plane's yield force over the tick; the law's threshold
    // taken here, at the haptic rate, so the dent does not depend on how the world's period cut the push).
    const double press_Ns =
        plane.deformable() ? std::max(0.0, -impulse_Ns.dot(plane.normal) - plane.yield_force_N * dt_s) : 0.0;
    ImpulseShare& share = last_shares_[static_cast<std::size_t>(last_share_count_++)];
    share = {plane.object_id, plane.dynamic(), impulse_Ns, angular_Nms, press_Ns};
    share.credit_J = std::max(0.0, impulse_Ns.dot(finger_velocity_mps));
    ObjectImpulse* entry = book(share, plane.deformable(), tick);
    if (entry && press_Ns > 0.0) {
      const Eigen::Vector3d& x_m = contact.proxy_m;
      entry->press_Ns += press_Ns;
      add_to(entry->press_point_Nsm, press_Ns * x_m);
      std::array<double, 6>& point2 = entry->press_point2_Nsm2;  // xx, xy, xz, yy, yz, zz
      point2[0] += press_Ns * x_m.x() * x_m.x();
      point2[1] += press_Ns * x_m.x() * x_m.y();
      point2[2] += press_Ns * x_m.x() * x_m.z();
      point2[3] += press_Ns * x_m.y() * x_m.y();
      point2[4] += press_Ns * x_m.y() * x_m.z();
      point2[5] += press_Ns * x_m.z() * x_m.z();
    }
  }
}

ObjectImpulse* ImpulseAccumulator::book(ImpulseShare& share, bool deformable, std::uint64_t tick) {
  ObjectImpulse* entry = share.dynamic || deformable ? entry_for(share.object_id) : nullptr;
  if (!entry) {
    if (share.dynamic || deformable) {
      dropped_Ns_ += share.impulse_Ns;
      ++dropped_shares_;
    } else {
      add_to(report_.static_impulse_Ns, share.impulse_Ns);
    }
    share.credit_J = 0.0;
    share.entry = nullptr;
    return nullptr;
  }
  add_to(entry->impulse_Ns, share.impulse_Ns);
  add_to(entry->angular_impulse_Nms, share.angular_impulse_Nms);
  // First moments in time (common/contract/frames.h ObjectImpulse): where in the world period this impulse belongs.
  add_to(entry->impulse_moment_Nss, share.impulse_Ns * report_.haptic_time_s);
  add_to(entry->angular_impulse_moment_Nmss, share.angular_impulse_Nms * report_.haptic_time_s);
  share.entry = entry;
  entry->hand_input_J += share.credit_J;
  entry->last_tick = tick;
  return entry;
}

void ImpulseAccumulator::add_shares(const ImpulseShare* shares, int count, std::uint64_t tick) {
  hand_tick_ = tick;
  last_share_count_ = 0;
  for (int k = 0; k < count; ++k) {
    ImpulseShare share = shares[k];
    share.yielding_Ns = 0.0;
    total_Ns_ += share.impulse_Ns;
    book(share, false, tick);
    if (last_share_count_ < static_cast<int>(last_shares_.size())) {
      last_shares_[static_cast<std::size_t>(last_share_count_++)] = share;
    }
  }
}

bool ImpulseAccumulator::pushed_dynamic() const {
  for (int j = 0; j < last_share_count_; ++j) {
    const ImpulseShare& share = last_shares_[static_cast<std::size_t>(j)];
    if (share.dynamic && share.entry != nullptr && share.impulse_Ns.norm() > 0.0) return true;
  }
  return false;
}

double ImpulseAccumulator::set_last_credit(double energy_J) {
  double weight_Ns = 0.0;
  for (int j = 0; j < last_share_count_; ++j) {
    const ImpulseShare& share = last_shares_[static_cast<std::size_t>(j)];
    if (share.dynamic && share.entry != nullptr) weight_Ns += share.impulse_Ns.norm();
  }
  const double total_J = energy_J > 0.0 && std::isfinite(energy_J) && weight_Ns > 0.0 ? energy_J : 0.0;
  double credited_J = 0.0;
  for (int j = 0; j < last_share_count_; ++j) {
    ImpulseShare& share = last_shares_[static_cast<std::size_t>(j)];
    if (share.entry == nullptr) continue;
    const double part_J = share.dynamic && weight_Ns > 0.0 ? total_J * share.impulse_Ns.norm() / weight_Ns : 0.0;
    share.entry->hand_input_J += part_J - share.credit_J;
    share.credit_J = part_J;
    credited_J += part_J;
  }
  return credited_J;
}

}  // namespace impetus
