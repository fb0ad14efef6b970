// SPDX-License-Identifier: Apache-2.0
#include "common/spidar/geometry.h"

#include "common/spidar/device_file.h"

#include <nlohmann/json.hpp>

#include <cstring>

namespace impetus {

SpidarGeometry load_spidar_geometry(const std::string& path) {
  using device_file::positive;
  const nlohmann::json document = device_file::read(path);
  device_file::check_keys(document, path, {"frame_side_m", "centre_m", "metres_per_count", "tension_min_N",
                                           "tension_max_N", "max_force_N"});
  using device_file::kMaxForce_N, device_file::kMaxFrameSide_m, device_file::kMaxMetresPerCount;
  SpidarGeometry geometry;
  geometry.frame_side_m = positive(document, path, "frame_side_m", geometry.frame_side_m, kMaxFrameSide_m);
  geometry.metres_per_count =
      positive(document, path, "metres_per_count", geometry.metres_per_count, kMaxMetresPerCount);
  geometry.tension_min_N = positive(document, path, "tension_min_N", geometry.tension_min_N, kMaxForce_N);
  geometry.tension_max_N = positive(document, path, "tension_max_N", geometry.tension_max_N, kMaxForce_N);
  geometry.max_force_N = positive(document, path, "max_force_N", geometry.max_force_N, kMaxForce_N);
  geometry.centre_m = device_file::point(document, path, "centre_m", geometry.centre_m, kMaxFrameSide_m);
  device_file::tension_range(path, geometry.tension_min_N, geometry.tension_max_N);
  return geometry;
}

SpidarDevice parse_device_spec(const std::string& spec) {
  SpidarDevice device;
  const std::string file = device_file::spec_file(spec, "spidar", "--device must be 'spidar' or 'spidar:FILE.json'");
  if (file.empty()) return device;
  device.source = file;
  device.geometry = load_spidar_geometry(file);
  return device;
}

std::uint64_t geometry_hash(const SpidarGeometry& geometry) {
  return device_file::hash_values({geometry.frame_side_m, geometry.centre_m[0], geometry.centre_m[1],
                                   geometry.centre_m[2], geometry.metres_per_count, geometry.tension_min_N,
                                   geometry.tension_max_N, geometry.max_force_N});
}

}  // namespace impetus
