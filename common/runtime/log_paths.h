// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where each endpoint's log goes when a node serves several (haptic_controller, spidar_sim): the path given for
// endpoint 0, and for endpoint k the same name with ".endpointK" before the extension (haptic.csv →
// haptic.endpoint1.csv), so a one-finger trial's files keep their names.

#include <cstdint>
#include <string>

namespace impetus {

inline std::string endpoint_log_path(const std::string& log_path, std::uint32_t endpoint) {
  if (endpoint == 0 || log_path.empty()) return log_path;
  const std::string suffix = ".endpoint" + std::to_string(endpoint);
  const std::size_t slash = log_path.find_last_of('/');
  const std::size_t dot = log_path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return log_path + suffix;
  return log_path.substr(0, dot) + suffix + log_path.substr(dot);
}

}  // namespace impetus
