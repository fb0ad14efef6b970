// SPDX-License-Identifier: Apache-2.0
#pragma once
// Writing one CSV row of numbers fast and exactly, the same way in every log.
//
// Numbers are written in the shortest form that reads back to the same double (std::to_chars), so a log reproduces a
// run's state bit for bit, two lockstep runs give byte-identical logs, and formatting costs a fraction of printf's
// "%.17g" — which matters because a lockstep trial logs every 1 kHz tick and its throughput is bounded by the logs.
// The row is built in a fixed buffer (no allocation) and handed to the stream in large pieces.

#include "common/contract/vec3.h"

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <ostream>

namespace impetus {

class CsvLine {
 public:
  // Which part of a row this line writes: a whole row (ended by a newline), or one piece of a row written in several
  // (the first piece, a middle one after a comma, the last one after a comma and ended by the newline).
  enum class Part { whole, first, middle, last };

  explicit CsvLine(std::ostream& out, Part part = Part::whole)
      : out_(out), first_(part == Part::whole || part == Part::first),
        newline_(part == Part::whole || part == Part::last) {}
  CsvLine(const CsvLine&) = delete;
  CsvLine& operator=(const CsvLine&) = delete;
  ~CsvLine() { end(); }

  CsvLine& number(double value) {
    separator();
    size_ = static_cast<std::size_t>(std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), value).ptr -
                                     buffer_.data());
    return *this;
  }
  CsvLine& integer(std::int64_t value) {
    separator();
    size_ = static_cast<std::size_t>(std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), value).ptr -
                                     buffer_.data());
    return *this;
  }
  template <std::size_t N>
  CsvLine& numbers(const std::array<double, N>& values) {
    for (double value : values) number(value);
    return *this;
  }
  template <class Vector3>
  CsvLine& vector(const Vector3& v) {
    return number(v[0]).number(v[1]).number(v[2]);
  }

  // Ends the row (or this piece of it) and writes out what is buffered. Idempotent.
  void end() {
    if (ended_) return;
    if (newline_) buffer_[size_++] = '\n';
    flush();
    ended_ = true;
  }

 private:
  // The longest double from to_chars is 24 characters; flushing with more than 32 left keeps every write in bounds.
  static constexpr std::size_t kReserve_chars = 32;

  void separator() {
    if (buffer_.size() - size_ < kReserve_chars) flush();
    if (!first_) buffer_[size_++] = ',';
    first_ = false;
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(size_));
    size_ = 0;
  }

  std::ostream& out_;
  std::array<char, 4096> buffer_;  // not cleared: only the first size_ characters are ever read
  std::size_t size_ = 0;
  bool first_ = true;
  bool newline_ = true;
  bool ended_ = false;
};

}  // namespace impetus
