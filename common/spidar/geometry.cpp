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
  SpidarGeometry geometry;
  // Bounds: a string frame of 10 m is a room-sized SPIDAR; an encoder count above 1 cm cannot resolve a contact;
  // 1 kN is beyond any string and motor a person should be tied to.
  constexpr double kMaxFrameSide_m = 10.0;
  constexpr double kMaxMetresPerCount = 0.01;
  constexpr double kMaxForce_N = 1000.0;
  geometry.frame_side_m = positive(document, path, "frame_side_m", geometry.frame_side_m, kMaxFrameSide_m);
  geometry.metres_per_count =
      positive(document, path, "metres_per_count", geometry.metres_per_count, kMaxMetresPerCount);
  geometry.tension_min_N = positive(document, path, "tension_min_N", geometry.tension_min_N, kMaxForce_N);
  geometry.tension_max_N = positive(document, path, "tension_max_N", geometry.tension_max_N, kMaxForce_N);
  geometry.max_force_N = positive(document, path, "max_force_N", geometry.max_force_N, kMaxForce_N);
  geometry.centre_m = device_file::point(document, path, "centre_m", geometry.centre_m, kMaxFrameSide_m);
  if (!(geometry.tension_min_N < geometry.tension_max_N)) {
    device_file::fail(path, "tension_max_N",
                      "must exceed tension_min_N (" + std::to_string(geometry.tension_min_N) + " N)");
  }
  return geometry;
}

SpidarDevice parse_device_spec(const std::string& spec) {
  SpidarDevice device;
  if (spec == "spidar") return device;
  const std::string prefix = "spidar:";
  if (spec.rfind(prefix, 0) != 0 || spec.size() == prefix.size()) {
    throw SpidarGeometryError("--device must be 'spidar' or 'spidar:FILE.json', got '" + spec + "'");
  }
  device.source = spec.substr(prefix.size());
  device.geometry = load_spidar_geometry(device.source);
  return device;
}

std::uint64_t geometry_hash(const SpidarGeometry& geometry) {
  // FNV-1a over the values' bytes, in a fixed order.
  const double values[] = {geometry.frame_side_m,     geometry.centre_m[0],  geometry.centre_m[1],
                           geometry.centre_m[2],      geometry.metres_per_count, geometry.tension_min_N,
                           geometry.tension_max_N,    geometry.max_force_N};
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (double value : values) {
    unsigned char bytes[sizeof(double)];
    std::memcpy(bytes, &value, sizeof bytes);
    for (unsigned char byte : bytes) hash = (hash ^ byte) * 0x100000001b3ull;
  }
  return hash;
}

}  // namespace impetus
