#include "common/impulse_ledger.h"

namespace impetus {

ImpulseLedger::ImpulseLedger(std::size_t id_count) : baselines_(id_count) {}

ImpulseDelta ImpulseLedger::take(std::uint64_t haptic_session, const ObjectImpulse& entry) {
  Baseline& baseline = baselines_[static_cast<std::size_t>(entry.object_id)];
  const bool same_counter = baseline.session == haptic_session && baseline.epoch == entry.epoch;
  if (!same_counter) {
    // A new counter starts at zero (link_types.h, ObjectImpulse::epoch).
    baseline = Baseline{haptic_session, entry.epoch, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  const Eigen::Vector3d total_Ns = to_eigen(entry.impulse_Ns);
  const Eigen::Vector3d total_angular_Nms = to_eigen(entry.angular_impulse_Nms);
  ImpulseDelta delta{total_Ns - baseline.impulse_Ns, total_angular_Nms - baseline.angular_impulse_Nms};
  baseline.impulse_Ns = total_Ns;
  baseline.angular_impulse_Nms = total_angular_Nms;
  return delta;
}

Eigen::Vector3d ImpulseLedger::take_static(std::uint64_t haptic_session, const Vec3& total_Ns) {
  if (static_baseline_.session != haptic_session) {
    static_baseline_ = Baseline{haptic_session, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  }
  const Eigen::Vector3d total = to_eigen(total_Ns);
  const Eigen::Vector3d delta_Ns = total - static_baseline_.impulse_Ns;
  static_baseline_.impulse_Ns = total;
  return delta_Ns;
}

}  // namespace impetus
