#pragma once
// The reader's side of the cumulative-impulse contract (DESIGN.md §2, ObjectImpulse in link_types.h).
//
// The haptic controller publishes, per object, the running total of the impulse it rendered since its session began.
// The world keeps what it has already applied of each total and applies only the difference, so a report read twice
// applies nothing twice, and reports the world never saw lose nothing (the next total contains them). A new haptic
// session or a new entry epoch starts a new running total from zero: the baseline is reset to zero, never subtracted
// from a restarted counter, so a restarted haptic controller cannot look like a huge impulse.

#include "common/link_types.h"
#include "common/vec3.h"

#include <cstdint>
#include <vector>

namespace impetus {

struct ImpulseDelta {
  Vec3 impulse_Ns{};
  Vec3 angular_impulse_Nms{};
};

class ImpulseLedger {
 public:
  explicit ImpulseLedger(std::size_t object_count) : baselines_(object_count) {}

  // Calls apply(object_id, ImpulseDelta) for each entry of a validated report whose total moved since the last call.
  // Entries naming an object outside [0, object_count) are skipped and counted in unknown_objects().
  template <class Apply>
  void consume(const HapticReport& report, Apply&& apply);

  std::uint64_t unknown_objects() const { return unknown_objects_; }

 private:
  struct Baseline {
    std::uint64_t session = 0;
    std::uint32_t epoch = 0;
    Vec3 impulse_Ns{};
    Vec3 angular_impulse_Nms{};
  };
  std::vector<Baseline> baselines_;
  std::uint64_t unknown_objects_ = 0;
};

template <class Apply>
void ImpulseLedger::consume(const HapticReport& report, Apply&& apply) {
  for (std::uint32_t k = 0; k < report.entry_count && k < kMaxImpulseEntries; ++k) {
    const ObjectImpulse& entry = report.entries[k];
    if (entry.object_id < 0 || static_cast<std::size_t>(entry.object_id) >= baselines_.size()) {
      ++unknown_objects_;
      continue;
    }
    Baseline& baseline = baselines_[static_cast<std::size_t>(entry.object_id)];
    if (baseline.session != report.haptic_session || baseline.epoch != entry.epoch) {
      baseline = Baseline{report.haptic_session, entry.epoch, {}, {}};
    }
    ImpulseDelta delta;
    bool moved = false;
    for (int a = 0; a < 3; ++a) {
      delta.impulse_Ns[a] = entry.impulse_Ns[a] - baseline.impulse_Ns[a];
      delta.angular_impulse_Nms[a] = entry.angular_impulse_Nms[a] - baseline.angular_impulse_Nms[a];
      moved = moved || delta.impulse_Ns[a] != 0.0 || delta.angular_impulse_Nms[a] != 0.0;
    }
    baseline.impulse_Ns = entry.impulse_Ns;
    baseline.angular_impulse_Nms = entry.angular_impulse_Nms;
    if (moved) apply(entry.object_id, delta);
  }
}

}  // namespace impetus
