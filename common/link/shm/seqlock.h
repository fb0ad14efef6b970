// SPDX-License-Identifier: Apache-2.0
#pragma once
// Single-writer, many-reader channel for one trivially-copyable frame in shared memory (docs/architecture.md §2).
//
// The writer never waits: it bumps the sequence word to odd, stores the payload, then bumps it to even. A reader polls
// the sequence word first (cheap, so it copies only when something new was published), copies the payload, and keeps
// the copy only if the sequence was even and unchanged across the copy — it never returns a torn frame. The payload
// lives in atomic 64-bit words so the concurrent copy is not a data race in the C++ memory model.
//
// Ordering without fences (ThreadSanitizer does not model atomic_thread_fence): the odd bump is an acq_rel
// read-modify-write (an exchange), so no payload store moves before it; payload words are stored with release and loaded with
// acquire, so a reader that sees any word of a newer write also sees that write's odd sequence on its second look.
// On x86 these are plain moves (one locked add per write), the same cost as the relaxed-plus-fences form.
//
// Exactly one writer per channel (one process, one thread). Readers may be in any process.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace impetus {

template <class T>
class SeqlockChannel {
  static_assert(std::is_trivially_copyable_v<T>, "a channel frame must be trivially copyable");
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "the sequence and payload words must be lock-free");

 public:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

  // Publishes a frame. Wait-free. Returns false if it found the sequence word odd at rest and repaired it.
  // `used_bytes` (default: all of it): only that prefix of the frame is stored and read back, so a frame with a large
  // fixed capacity and a small fill (a snapshot of a 2-body scene in room for 2048) costs what it carries.
  //
  // At rest the word is even; only this writer changes it. An odd word at rest is a write that never finished (a
  // writer killed mid-write) or a stray write into the segment: readers would take every frame as mid-write and the
  // channel would be dead for good. So the writer starts from the next even value: the channel recovers at its next
  // write.
  bool write(const T& frame, std::size_t used_bytes = sizeof(T)) {
    const std::size_t words = used_bytes >= sizeof(T) ? kWords : (used_bytes + 7) / 8;
    std::uint64_t seq = sequence_.load(std::memory_order_relaxed);
    const bool settled = (seq & 1u) == 0;
    seq += settled ? 0 : 1;
    sequence_.exchange(seq + 1, std::memory_order_acq_rel);  // now odd: a write is under way
    used_words_.store(words, std::memory_order_release);
    const auto* bytes = reinterpret_cast<const unsigned char*>(&frame);
    for (std::size_t w = 0; w < words; ++w) {
      std::uint64_t word = 0;
      std::memcpy(&word, bytes + w * 8, w + 1 < kWords ? 8 : sizeof(T) - w * 8);
      payload_[w].store(word, std::memory_order_release);
    }
    sequence_.store(seq + 2, std::memory_order_release);
    return settled;
  }

  // The current sequence number: even and > 0 once something was written; compare with a previous value to see
  // whether there is news without copying the payload.
  std::uint64_t sequence() const { return sequence_.load(std::memory_order_acquire); }

  // Copies the latest frame into `out` if it was published after `last_sequence` (pass 0 to accept any frame).
  // Returns false if nothing new was published or the writer was mid-write `max_attempts` times in a row (the caller
  // retries on its next tick instead of spinning). On success `last_sequence` is updated and, if `copied_bytes` is
  // given, it receives how many leading bytes of `out` were written (the writer's `used_bytes`, rounded up to 8; the
  // rest of `out` is left as it was).
  bool try_read(T& out, std::uint64_t& last_sequence, int max_attempts = 4, std::size_t* copied_bytes = nullptr) const {
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
      const std::uint64_t before = sequence_.load(std::memory_order_acquire);
      if (before == last_sequence || before == 0) return false;
      if (before & 1u) continue;
      const std::uint64_t used = used_words_.load(std::memory_order_acquire);
      const std::size_t words = used < kWords ? static_cast<std::size_t>(used) : kWords;  // a scribbled count is capped
      auto* bytes = reinterpret_cast<unsigned char*>(&out);
      for (std::size_t w = 0; w < words; ++w) {
        const std::uint64_t word = payload_[w].load(std::memory_order_acquire);
        std::memcpy(bytes + w * 8, &word, w + 1 < kWords ? 8 : sizeof(T) - w * 8);
      }
      // The acquire loads above keep this load after them.
      if (sequence_.load(std::memory_order_relaxed) == before) {
        last_sequence = before;
        if (copied_bytes != nullptr) *copied_bytes = words == kWords ? sizeof(T) : words * 8;
        return true;
      }
    }
    return false;
  }

  // Used only when a segment is created (no concurrent access).
  void reset() {
    sequence_.store(0, std::memory_order_relaxed);
    used_words_.store(0, std::memory_order_relaxed);
    for (auto& word : payload_) word.store(0, std::memory_order_relaxed);
  }

 private:
  std::atomic<std::uint64_t> sequence_{0};
  std::atomic<std::uint64_t> used_words_{0};  // payload words of the latest write; changed only inside its odd window
  std::atomic<std::uint64_t> payload_[kWords];
};

}  // namespace impetus
