// SPDX-License-Identifier: Apache-2.0
#pragma once
// System names of the segments for a `--shm NAME` (docs/architecture.md §2: one segment per link).

#include <string>
#include <string_view>

namespace impetus {

// Why `shm` cannot name a link's segments, or "" if it can: 1 to 200 of A–Z a–z 0–9 _ - ., not starting with a dot
// (the segments would be hidden files in /dev/shm) and never a slash (POSIX names have none after the first).
inline std::string shm_name_problem(std::string_view shm) {
  constexpr std::size_t kMaxLength = 200;  // the segment suffixes and the 255-byte file-name limit
  if (shm.empty()) return "must not be empty";
  if (shm.size() > kMaxLength) return "must be at most " + std::to_string(kMaxLength) + " characters";
  if (shm.front() == '.') return "must not start with '.' (its segments would be hidden files in /dev/shm)";
  for (const char c : shm) {
    const bool allowed = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                         c == '-' || c == '.';
    if (!allowed) return "may hold only letters, digits, '_', '-' and '.'";
  }
  return "";
}

inline std::string world_link_name(const std::string& shm) { return shm + ".world"; }
// Finger k of a several-finger device has its own port: "<shm>.device" for finger 0, "<shm>.device<k>" after it.
inline std::string device_port_name(const std::string& shm, unsigned finger = 0) {
  return finger == 0 ? shm + ".device" : shm + ".device" + std::to_string(finger);
}
inline std::string world_view_name(const std::string& shm) { return shm + ".view"; }
// The web hand device's touch port: the viewer's page steers it.
inline std::string touch_port_name(const std::string& shm) { return shm + ".touch"; }

}  // namespace impetus
