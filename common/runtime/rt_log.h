// SPDX-License-Identifier: Apache-2.0
#pragma once
// Logging out of a real-time loop: the loop copies a fixed-size row into a preallocated single-producer /
// single-consumer ring; a separate thread drains the ring into a CSV file. The loop never allocates, locks or does I/O.
//
// Overflow policy: in real time a full ring drops the row and counts it (the loop must not wait on the disk); in
// lockstep the producer waits for space instead, because a lockstep log must be complete to be reproducible.
//
// A failed write (disk full) is reported by the drain thread when it happens (write_watch.h) and failed() says so; the
// drain keeps emptying the ring, so a lockstep producer never waits on a file that cannot take the rows.

#include "common/runtime/write_watch.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace impetus {

enum class LogOverflow { drop, wait };

template <class Row>
class RtLog {
  static_assert(std::is_trivially_copyable_v<Row>);

 public:
  using Formatter = std::function<void(std::ostream&, const Row&)>;

  // Opens `path` (throws std::runtime_error naming the path if it cannot), writes `header` and starts the drain thread.
  // `program` names the writer in the message of a failed write.
  RtLog(const std::string& path, const std::string& header, Formatter format, std::size_t capacity,
        LogOverflow overflow, const std::string& program = "log")
      : file_buffer_(std::make_unique<char[]>(kFileBufferBytes)), format_(std::move(format)), rows_(capacity),
        overflow_(overflow), watch_(program, path) {
    file_.rdbuf()->pubsetbuf(file_buffer_.get(), kFileBufferBytes);  // before open(), where it takes effect
    file_.open(path);
    if (!file_) throw std::runtime_error("cannot open log file '" + path + "' for writing");
    file_ << header << '\n';
    drainer_ = std::thread([this] { drain_loop(); });
  }
  ~RtLog() { close(); }
  RtLog(const RtLog&) = delete;
  RtLog& operator=(const RtLog&) = delete;

  // Producer (one thread). Real-time safe with LogOverflow::drop.
  void push(const Row& row) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    while (head - tail_.load(std::memory_order_acquire) >= rows_.size()) {
      if (overflow_ == LogOverflow::drop) {
        dropped_.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    rows_[head % rows_.size()] = row;
    head_.store(head + 1, std::memory_order_release);
  }

  // Producer: several rows that the drain must see together or not at all (pieces of one CSV line), at most the
  // capacity. Waits for room for all of them in lockstep; with LogOverflow::drop drops them all if there is none.
  void push_all(std::span<const Row> rows) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (rows.size() > rows_.size()) {
      dropped_.fetch_add(rows.size(), std::memory_order_relaxed);  // could never fit: a caller's sizing error
      return;
    }
    while (head + rows.size() - tail_.load(std::memory_order_acquire) > rows_.size()) {
      if (overflow_ == LogOverflow::drop) {
        dropped_.fetch_add(rows.size(), std::memory_order_relaxed);
        return;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    for (std::size_t k = 0; k < rows.size(); ++k) rows_[(head + k) % rows_.size()] = rows[k];
    head_.store(head + rows.size(), std::memory_order_release);
  }

  // Any thread: formats the oldest queued row, unless none is queued or another thread is draining, and says whether
  // it did. A lockstep process calls it while it waits for its turn (lockstep.h LockstepIdleWork): the rows are then
  // formatted in time the process would only spend polling, instead of by the drain thread, which on a machine of
  // two cores must take one from a process in the turn. Never blocks; the drain thread flushes the file.
  bool drain_one() {
    if (draining_.test_and_set(std::memory_order_acquire)) return false;
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    const bool queued = tail != head_.load(std::memory_order_acquire);
    if (queued) {
      format_(file_, rows_[tail % rows_.size()]);
      tail_.store(tail + 1, std::memory_order_release);
      unflushed_.store(true, std::memory_order_relaxed);
    }
    draining_.clear(std::memory_order_release);
    return queued;
  }

  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  // Whether a write to the file failed (reported on stderr when it happened).
  bool failed() const { return watch_.failed(); }

  // Drains what is left, stops the thread and flushes the file. Idempotent.
  void close() {
    if (!drainer_.joinable()) return;
    stopping_.store(true, std::memory_order_release);
    drainer_.join();
    file_.flush();
    watch_.check(file_);
  }

 private:
  void drain_loop() {
    for (;;) {
      const bool stopping = stopping_.load(std::memory_order_acquire);
      // A thread in drain_one() has the file: this pass is skipped, the next one (or the last, below) catches up.
      if (!draining_.test_and_set(std::memory_order_acquire)) {
        std::uint64_t tail = tail_.load(std::memory_order_relaxed);
        const std::uint64_t head = head_.load(std::memory_order_acquire);
        const bool wrote = tail != head || unflushed_.exchange(false, std::memory_order_relaxed);
        for (; tail != head; ++tail) format_(file_, rows_[tail % rows_.size()]);
        tail_.store(tail, std::memory_order_release);
        if (wrote && !watch_.failed()) {
          file_.flush();  // so a full disk is noticed now, not at exit
          watch_.check(file_);
        }
        draining_.clear(std::memory_order_release);
        if (stopping && tail == head_.load(std::memory_order_acquire)) return;
      }
      // 2 ms keeps the ring far from full at 1 kHz with any sane capacity while costing almost no CPU.
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

  // The file's buffer: a lockstep run formats hundreds of thousands of rows a second, and the stream's default 8 KB
  // makes a write system call every ~30 rows (a third of a row's cost here). The drain thread still flushes every
  // 2 ms, so a real-time log is no later on disk than before.
  static constexpr std::size_t kFileBufferBytes = std::size_t{1} << 20;
  std::unique_ptr<char[]> file_buffer_;  // outlives file_ (declared first)
  std::ofstream file_;
  Formatter format_;
  std::vector<Row> rows_;
  LogOverflow overflow_;
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> stopping_{false};
  std::atomic_flag draining_;           // held by whichever thread is formatting rows into the file
  std::atomic<bool> unflushed_{false};  // drain_one() wrote rows the drain thread has not flushed yet
  WriteWatch watch_;
  std::thread drainer_;
};

}  // namespace impetus
