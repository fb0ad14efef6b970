#include "haptic_controller/impulse_accumulator.h"

namespace impetus {
namespace {

void add_to(Vec3& total, const Eigen::Vector3d& delta) {
  for (int a = 0; a < 3; ++a) total[a] += delta[a];
}

}  // namespace

ImpulseAccumulator::ImpulseAccumulator(std::uint64_t haptic_session) { report_.haptic_session = haptic_session; }

void ImpulseAccumulator::on_plane_frame(const PlaneFrame& frame) {
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
  last_share_count_ = 0;
  if (reaction_Ns.isZero(0.0)) return;  // nothing to share (and no multiplier is trusted when the force was zeroed)

  double weight_sum = 0.0;
  for (int j = 0; j < contact.active_count; ++j) weight_sum += contact.active[j].multiplier_m;
  if (contact.active_count == 0) {
    dropped_Ns_ += reaction_Ns;
    ++dropped_shares_;
    return;
  }
  for (int j = 0; j < contact.active_count; ++j) {
    // Multipliers share the load; if all are zero (touching with no load) share equally.
    const double share = weight_sum > 0.0 ? contact.active[j].multiplier_m / weight_sum : 1.0 / contact.active_count;
    const Eigen::Vector3d impulse_Ns = share * reaction_Ns;
    const ContactPlane& plane = planes.planes[contact.active[j].plane];
    const Eigen::Vector3d angular_Nms = (contact.proxy_m - plane.com_m).cross(impulse_Ns);
    last_shares_[static_cast<std::size_t>(last_share_count_++)] = {plane.object_id, plane.dynamic(), impulse_Ns,
                                                                   angular_Nms};
    if (!plane.dynamic()) {
      add_to(report_.static_impulse_Ns, impulse_Ns);
      continue;
    }
    ObjectImpulse* entry = entry_for(plane.object_id);
    if (!entry) {
      dropped_Ns_ += impulse_Ns;
      ++dropped_shares_;
      continue;
    }
    add_to(entry->impulse_Ns, impulse_Ns);
    add_to(entry->angular_impulse_Nms, angular_Nms);
    // First moments in time (link_types.h ObjectImpulse): where in the world period this impulse belongs.
    add_to(entry->impulse_moment_Nss, impulse_Ns * report_.haptic_time_s);
    add_to(entry->angular_impulse_moment_Nmss, angular_Nms * report_.haptic_time_s);
    entry->last_tick = tick;
  }
}

}  // namespace impetus
