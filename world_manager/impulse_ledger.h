// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world's side of "no impulse is lost or counted twice" (docs/architecture.md §2).
//
// Each endpoint of each haptic session publishes, per object, a running total of impulse since its entry for that
// object was (re)allocated, keyed by (haptic session, endpoint, object, epoch). The ledger remembers the last total it
// saw per (haptic session, endpoint, object) and hands out the difference (of the hand's input behind it too). A
// counter it has not seen, or whose epoch changed, has restarted from zero, so its baseline is zero: a restarted haptic controller never causes a burst, a
// repeated report yields nothing, and two endpoints pushing the same object never cancel each other's baselines.

#include "common/contract/frames.h"

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace impetus {

// The moments of the push into an object's surface (common/contract/frames.h ObjectImpulse::press_*), over some span
// of haptic ticks: what a deformable object dents by (deform/press_path.h).
struct PressMoments {
  double push_Ns = 0.0;                                        // Σ p_k
  Eigen::Vector3d point_Nsm = Eigen::Vector3d::Zero();         // Σ p_k·x_k, world frame
  Eigen::Matrix3d point2_Nsm2 = Eigen::Matrix3d::Zero();       // Σ p_k·x_k·x_kᵀ, symmetric

  static PressMoments of(const ObjectImpulse& entry);
  PressMoments operator-(const PressMoments& other) const;
  PressMoments scaled(double factor) const;  // every moment times `factor` (a clipped report's push)
  bool all_finite() const;
};

struct ImpulseDelta {
  Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();  // about the centre of mass, world frame
  double hand_input_J = 0.0;  // the energy the hand put in behind it (ObjectImpulse::hand_input_J)
  PressMoments press;         // where the surface was pressed (ObjectImpulse::press_*)
};

// Whose counters: one endpoint of one haptic session.
struct CounterOwner {
  std::uint64_t haptic_session = 0;
  EndpointId endpoint = 0;
  auto operator<=>(const CounterOwner&) const = default;
};

class ImpulseLedger {
 public:
  // Ids 0..id_count-1 are tracked (the scene objects and the floor).
  explicit ImpulseLedger(std::size_t id_count);

  // The impulse of `entry` not yet taken, and `entry` becomes the new baseline. entry.object_id must be < id_count.
  ImpulseDelta take(const CounterOwner& owner, const ObjectImpulse& entry);

  // The same for the report's cumulative static impulse (one counter per owner).
  Eigen::Vector3d take_static(const CounterOwner& owner, const Vec3& total_Ns);

 private:
  struct Baseline {
    bool seen = false;
    std::uint32_t epoch = 0;
    Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();
    double hand_input_J = 0.0;
    PressMoments press;
  };
  struct OwnerBaselines {
    std::vector<Baseline> objects;
    Eigen::Vector3d static_Ns = Eigen::Vector3d::Zero();
  };
  OwnerBaselines& baselines_of(const CounterOwner& owner);

  std::size_t id_count_;
  std::map<CounterOwner, OwnerBaselines> owners_;
};

}  // namespace impetus
