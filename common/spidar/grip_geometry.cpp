// SPDX-License-Identifier: Apache-2.0
#include "common/spidar/grip_geometry.h"

#include <nlohmann/json.hpp>

#include <cstring>

namespace impetus {

SpidarGripGeometry load_grip_geometry(const std::string& path) {
  using device_file::positive;
  const nlohmann::json document = device_file::read(path);
  device_file::check_keys(document, path, {"frame_side_m", "centre_m", "grip_radius_m", "metres_per_count",
                                           "tension_min_N", "tension_max_N"});
  using device_file::kMaxForce_N, device_file::kMaxFrameSide_m, device_file::kMaxMetresPerCount;
  SpidarGripGeometry geometry;
  geometry.frame_side_m = positive(document, path, "frame_side_m", geometry.frame_side_m, kMaxFrameSide_m);
  geometry.centre_m = device_file::point(document, path, "centre_m", geometry.centre_m, kMaxFrameSide_m);
  // The grip moves only where its centre is farther than its radius from every face (grip_sim.h
  // grip_point_problem): a grip as wide as a quarter of the frame leaves half the frame's side to move in.
  geometry.grip_radius_m =
      positive(document, path, "grip_radius_m", geometry.grip_radius_m, 0.25 * geometry.frame_side_m);
  geometry.metres_per_count =
      positive(document, path, "metres_per_count", geometry.metres_per_count, kMaxMetresPerCount);
  geometry.tension_min_N = positive(document, path, "tension_min_N", geometry.tension_min_N, kMaxForce_N);
  geometry.tension_max_N = positive(document, path, "tension_max_N", geometry.tension_max_N, kMaxForce_N);
  device_file::tension_range(path, geometry.tension_min_N, geometry.tension_max_N);
  return geometry;
}

GripDevice parse_grip_spec(const std::string& spec) {
  GripDevice device;
  const std::string file = device_file::spec_file(spec, "grip", "the device must be 'grip' or 'grip:FILE.json'");
  if (file.empty()) return device;
  device.source = file;
  device.geometry = load_grip_geometry(file);
  return device;
}

std::uint64_t grip_geometry_hash(const SpidarGripGeometry& geometry) {
  // The values after a tag (its string count), so that a grip device never hashes as a 4-string one of the same
  // numbers.
  return device_file::hash_values({8.0, geometry.frame_side_m, geometry.centre_m[0], geometry.centre_m[1],
                                   geometry.centre_m[2], geometry.grip_radius_m, geometry.metres_per_count,
                                   geometry.tension_min_N, geometry.tension_max_N});
}

}  // namespace impetus
