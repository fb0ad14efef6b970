// SPDX-License-Identifier: Apache-2.0
#pragma once
// A delay line for the in-process world link (inproc_world_link.h): values go in stamped with the haptic tick they
// were sent at and come out once `delay_ticks` ticks have passed, newest first. Both kinds of traffic on the world link
// only ever need their newest value (a plane frame is a snapshot, a report carries running totals), so a due value
// replaces every older one.
//
// Fixed capacity, allocated by reset(); push() and take_newest_due() never allocate, lock or throw, so the 1 kHz servo
// may call them. Not thread-safe: one thread (the lockstep run's) uses it. Deterministic: the outcome depends only on
// the sequence of calls and their ticks.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace impetus {

template <class T>
class DelayLine {
 public:
  // What take_newest_due() hands out: the newest value due, and its place in the order of pushes (1, 2, ...), so a
  // receiver can tell a new value from the one it already took. `value` is null while nothing is due.
  struct Due {
    const T* value = nullptr;
    std::uint64_t sequence = 0;
  };

  // Empties the line and makes room for `capacity` values (at least 1), each held back `delay_ticks` ticks.
  // Allocates: call it when the link is built or a node attaches, never on the 1 kHz path.
  void reset(std::uint64_t delay_ticks, std::size_t capacity) {
    delay_ticks_ = delay_ticks;
    entries_.assign(capacity < 1 ? 1 : capacity, Entry{});
    first_ = 0;
    count_ = 0;
    pushed_ = 0;
    dropped_ = 0;
  }

  // Sends `value` at tick `sent_tick` (ticks never decrease from one push to the next). A full line drops its oldest
  // value and counts it (dropped()): the caller sizes the line for what can be in flight, and a receiver that stopped
  // taking values must not make the sender wait or allocate.
  void push(std::uint64_t sent_tick, const T& value) {
    if (count_ == entries_.size()) {
      first_ = next(first_);
      --count_;
      ++dropped_;
    }
    Entry& entry = entries_[(first_ + count_) % entries_.size()];
    entry.sent_tick = sent_tick;
    entry.sequence = ++pushed_;
    // Frames and reports are copied by their used part (frames.h copy_used): a whole frame is ~56 KB.
    if constexpr (requires { copy_used(value, entry.value); }) {
      copy_used(value, entry.value);
    } else {
      entry.value = value;
    }
    ++count_;
  }

  // The newest value sent at a tick ≤ now_ticks − delay_ticks, i.e. due by tick now_ticks (null if none is). Older due
  // values are dropped (only the newest is ever wanted); the newest due one stays until a newer one is due, so asking
  // again returns it again with the same sequence.
  Due take_newest_due(std::uint64_t now_ticks) {
    // sent + delay ≤ now rather than sent ≤ now − delay: no unsigned wrap while now < delay.
    while (count_ > 1 && is_due(entries_[next(first_)], now_ticks)) {
      first_ = next(first_);
      --count_;
    }
    if (count_ == 0 || !is_due(entries_[first_], now_ticks)) return {};
    return {&entries_[first_].value, entries_[first_].sequence};
  }

  std::uint64_t delay_ticks() const { return delay_ticks_; }
  std::size_t capacity() const { return entries_.size(); }
  std::size_t size() const { return count_; }            // values held: the newest due one and those in flight
  std::uint64_t dropped() const { return dropped_; }     // values a full line pushed out

 private:
  struct Entry {
    std::uint64_t sent_tick = 0;
    std::uint64_t sequence = 0;
    T value{};
  };

  bool is_due(const Entry& entry, std::uint64_t now_ticks) const { return entry.sent_tick + delay_ticks_ <= now_ticks; }
  std::size_t next(std::size_t index) const { return index + 1 == entries_.size() ? 0 : index + 1; }

  std::vector<Entry> entries_ = std::vector<Entry>(1);
  std::size_t first_ = 0;  // oldest value held
  std::size_t count_ = 0;
  std::uint64_t pushed_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t delay_ticks_ = 0;
};

}  // namespace impetus
