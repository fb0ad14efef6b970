// SPDX-License-Identifier: Apache-2.0
#include "world_manager/impulse_ledger.h"

#include <cmath>

namespace impetus {

PressMoments PressMoments::of(const ObjectImpulse& entry) {
  const std::array<double, 6>& m = entry.press_point2_Nsm2;  // xx, xy, xz, yy, yz, zz
  Eigen::Matrix3d point2_Nsm2;
  point2_Nsm2 << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
  return {entry.press_Ns, to_eigen(entry.press_point_Nsm), point2_Nsm2};
}

PressMoments PressMoments::operator-(const PressMoments& other) const {
  return {push_Ns - other.push_Ns, point_Nsm - other.point_Nsm, point2_Nsm2 - other.point2_Nsm2};
}

PressMoments PressMoments::scaled(double factor) const {
  return {factor * push_Ns, factor * point_Nsm, factor * point2_Nsm2};
}

bool PressMoments::all_finite() const {
  return std::isfinite(push_Ns) && point_Nsm.allFinite() && point2_Nsm2.allFinite();
}

ImpulseLedger::ImpulseLedger(std::size_t id_count) : id_count_(id_count) {}

ImpulseLedger::OwnerBaselines& ImpulseLedger::baselines_of(const CounterOwner& owner) {
  auto [it, inserted] = owners_.try_emplace(owner);
  if (inserted) it->second.objects.resize(id_count_);
  return it->second;
}

ImpulseDelta ImpulseLedger::take(const CounterOwner& owner, const ObjectImpulse& entry) {
  Baseline& baseline = baselines_of(owner).objects[static_cast<std::size_t>(entry.object_id)];
  if (!baseline.seen || baseline.epoch != entry.epoch) {
    // A new counter starts at zero (contract/frames.h, ObjectImpulse::epoch).
    baseline = Baseline{true, entry.epoch, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0, PressMoments{}};
  }
  const Eigen::Vector3d total_Ns = to_eigen(entry.impulse_Ns);
  const Eigen::Vector3d total_angular_Nms = to_eigen(entry.angular_impulse_Nms);
  const PressMoments press = PressMoments::of(entry);
  ImpulseDelta delta{total_Ns - baseline.impulse_Ns, total_angular_Nms - baseline.angular_impulse_Nms,
                     entry.hand_input_J - baseline.hand_input_J, press - baseline.press};
  baseline.press = press;
  baseline.impulse_Ns = total_Ns;
  baseline.angular_impulse_Nms = total_angular_Nms;
  baseline.hand_input_J = entry.hand_input_J;
  return delta;
}

Eigen::Vector3d ImpulseLedger::take_static(const CounterOwner& owner, const Vec3& total_Ns) {
  Eigen::Vector3d& baseline_Ns = baselines_of(owner).static_Ns;
  const Eigen::Vector3d total = to_eigen(total_Ns);
  const Eigen::Vector3d delta_Ns = total - baseline_Ns;
  baseline_Ns = total;
  return delta_Ns;
}

}  // namespace impetus
