// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/write_watch.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace impetus {

bool WriteWatch::check(const std::ostream& out) {
  if (out.good()) return true;
  if (!failed_.exchange(true, std::memory_order_acq_rel)) {
    // errno still holds the failed write's reason when the stream's flush was the last call; otherwise it is generic.
    const int reason = errno;
    std::fprintf(stderr, "%s: error: writing '%s' failed (%s); what is written from now on is lost\n", program_.c_str(),
                 path_.c_str(), reason != 0 ? std::strerror(reason) : "I/O error");
  }
  return false;
}

}  // namespace impetus
