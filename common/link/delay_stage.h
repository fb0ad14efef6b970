// SPDX-License-Identifier: Apache-2.0
#pragma once
// A delay and loss stage for what a real-time link receives (the DDS link's, dds/dds_world_link.h): each value that
// arrives is either lost (link_loss.h) or held back until a fixed time after its arrival, and the receiver sees only
// the newest value due. For experiments on a network this kernel cannot slow down (no netem): off by default, and a
// stage with no delay and no loss is not used at all.
//
// Fixed capacity, allocated by reset(); push() and take_due() never allocate, lock or throw. A full stage drops its
// oldest value and counts it (dropped()): both kinds of traffic need only their newest value (a frame is a snapshot, a
// report carries running totals), so a dropped one in flight only means the receiver skips it. Not thread-safe: one
// receiving thread uses it. Times are steady-clock nanoseconds, non-decreasing from one push to the next.

#include "common/link/link_loss.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace impetus {

template <class T>
class DelayStage {
 public:
  // Holds each value `delay_ns` (≥ 0) after it arrives, with room for `capacity` in flight (at least 1), and loses
  // packets by `loss` from stream `stream`. Allocates.
  void reset(std::int64_t delay_ns, std::size_t capacity, const LinkLoss& loss, std::uint64_t stream) {
    delay_ns_ = delay_ns > 0 ? delay_ns : 0;
    entries_.assign(capacity < 1 ? 1 : capacity, Entry{});
    first_ = 0;
    count_ = 0;
    loss_ = LossProcess(loss, stream);
    active_ = delay_ns_ > 0 || loss.rate > 0.0;
  }
  // Whether the stage does anything (a delay or a loss); an inactive stage must not be used.
  bool active() const { return active_; }

  // A value that arrived at `now_ns`: lost, or held until now_ns + delay.
  void push(std::int64_t now_ns, const T& value) {
    if (loss_.lose()) return;
    if (count_ == entries_.size()) {
      first_ = next(first_);
      --count_;
      ++dropped_;
    }
    Entry& entry = entries_[(first_ + count_) % entries_.size()];
    entry.due_ns = now_ns + delay_ns_;
    entry.value = value;
    ++count_;
  }

  // The newest value due by `now_ns` not handed out before (null if none); older due ones are skipped.
  const T* take_due(std::int64_t now_ns) {
    const T* newest = nullptr;
    while (count_ > 0 && entries_[first_].due_ns <= now_ns) {
      newest = &entries_[first_].value;
      first_ = next(first_);
      --count_;
    }
    return newest;  // valid until the next push (its slot is free again)
  }

  // When the oldest value held becomes due (steady-clock ns); the largest value if none is held.
  std::int64_t next_due_ns() const {
    return count_ > 0 ? entries_[first_].due_ns : std::numeric_limits<std::int64_t>::max();
  }

  std::uint64_t lost() const { return loss_.lost(); }
  std::uint64_t dropped() const { return dropped_; }

 private:
  struct Entry {
    std::int64_t due_ns = 0;
    T value{};
  };
  std::size_t next(std::size_t index) const { return index + 1 == entries_.size() ? 0 : index + 1; }

  std::vector<Entry> entries_ = std::vector<Entry>(1);
  std::size_t first_ = 0;
  std::size_t count_ = 0;
  std::int64_t delay_ns_ = 0;
  LossProcess loss_;
  bool active_ = false;
  std::uint64_t dropped_ = 0;
};

}  // namespace impetus
