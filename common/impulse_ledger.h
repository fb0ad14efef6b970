#pragma once
// The world's side of "no impulse is lost or counted twice" (DESIGN.md §2).
//
// The haptic side publishes, per object, a running total of impulse since its entry for that object was (re)allocated,
// keyed by (haptic_session, object_id, epoch). The ledger remembers the last total it saw per object and hands out the
// difference. When the session or the epoch differ from the remembered ones the counter has restarted from zero, so
// the baseline is zero: a restarted haptic controller never causes a burst, and a repeated report yields nothing.

#include "common/link_types.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace impetus {

struct ImpulseDelta {
  Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();  // about the centre of mass, world frame
};

class ImpulseLedger {
 public:
  // Ids 0..id_count-1 are tracked (the scene objects and the floor).
  explicit ImpulseLedger(std::size_t id_count);

  // The impulse of `entry` not yet taken, and `entry` becomes the new baseline. entry.object_id must be < id_count.
  ImpulseDelta take(std::uint64_t haptic_session, const ObjectImpulse& entry);

  // The same for the report's cumulative static impulse (one counter per haptic session).
  Eigen::Vector3d take_static(std::uint64_t haptic_session, const Vec3& total_Ns);

 private:
  struct Baseline {
    std::uint64_t session = 0;  // 0: nothing seen yet (a live session is nonzero)
    std::uint32_t epoch = 0;
    Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_impulse_Nms = Eigen::Vector3d::Zero();
  };
  std::vector<Baseline> baselines_;
  Baseline static_baseline_;
};

}  // namespace impetus
