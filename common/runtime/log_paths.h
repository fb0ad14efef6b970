// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where each endpoint's log goes when a node serves several (haptic_controller, spidar_sim): the path given for
// endpoint 0, and for endpoint k the same name with ".endpointK" before the extension (haptic.csv →
// haptic.endpoint1.csv), so a one-finger trial's files keep their names. A tool's pose log sits beside its haptic log
// with ".tool" before the extension (haptic.csv → haptic.tool.csv).

#include <cstdint>
#include <string>

namespace impetus {

// `log_path` with `suffix` before its extension (or at its end if it has none).
inline std::string log_path_with(const std::string& log_path, const std::string& suffix) {
  const std::size_t slash = log_path.find_last_of('/');
  const std::size_t dot = log_path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return log_path + suffix;
  return log_path.substr(0, dot) + suffix + log_path.substr(dot);
}

inline std::string endpoint_log_path(const std::string& log_path, std::uint32_t endpoint) {
  if (endpoint == 0 || log_path.empty()) return log_path;
  return log_path_with(log_path, ".endpoint" + std::to_string(endpoint));
}

inline std::string tool_log_path(const std::string& log_path) {
  return log_path.empty() ? log_path : log_path_with(log_path, ".tool");
}

}  // namespace impetus
