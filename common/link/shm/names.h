// SPDX-License-Identifier: Apache-2.0
#pragma once
// System names of the segments for a `--shm NAME` (docs/architecture.md §2: one segment per link).

#include <string>

namespace impetus {

inline std::string world_link_name(const std::string& shm) { return shm + ".world"; }
// Finger k of a several-finger device has its own port: "<shm>.device" for finger 0, "<shm>.device<k>" after it.
inline std::string device_port_name(const std::string& shm, unsigned finger = 0) {
  return finger == 0 ? shm + ".device" : shm + ".device" + std::to_string(finger);
}
inline std::string world_view_name(const std::string& shm) { return shm + ".view"; }

}  // namespace impetus
