// SPDX-License-Identifier: Apache-2.0
#pragma once
// A log or output file whose writes must not fail silently: the first failed write (disk full, I/O error) is reported
// on stderr when it is noticed, naming the program, the file and the system's reason, and is remembered so the
// program can exit non-zero. Not for the 1 kHz path (it prints); RtLog's drain thread and the slow loops use it.

#include <atomic>
#include <ostream>
#include <string>

namespace impetus {

class WriteWatch {
 public:
  WriteWatch(std::string program, std::string path) : program_(std::move(program)), path_(std::move(path)) {}

  // Whether `out` is still good; on its first failure prints
  //     PROGRAM: error: writing 'PATH' failed (REASON); what is written from now on is lost
  // and remembers it. `out` should have been flushed first, or a failure may still sit in its buffer.
  bool check(const std::ostream& out);

  bool failed() const { return failed_.load(std::memory_order_acquire); }
  const std::string& path() const { return path_; }

 private:
  std::string program_;
  std::string path_;
  std::atomic<bool> failed_{false};
};

}  // namespace impetus
