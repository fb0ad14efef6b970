// SPDX-License-Identifier: Apache-2.0
#include "common/spidar/geometry.h"

#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>

namespace impetus {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& reason) {
  throw SpidarGeometryError(path + ": " + key + ": " + reason);
}

// A value in (0, highest]: each key's bound is given with its reason where the key is read.
double positive(const nlohmann::json& document, const std::string& path, const char* key, double fallback,
                double highest) {
  if (!document.contains(key)) return fallback;
  const nlohmann::json& value = document.at(key);
  if (!value.is_number()) fail(path, key, "must be a number, got " + quote_json(value));
  const double number = value.get<double>();
  if (!std::isfinite(number) || !(number > 0.0) || number > highest) {
    fail(path, key, "must be positive and at most " + readable(highest) + ", got " + quote_json(value));
  }
  return number;
}

}  // namespace

SpidarGeometry load_spidar_geometry(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SpidarGeometryError(path + ": cannot open the device file");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {  // parse errors, and numbers too large for a double
    throw SpidarGeometryError(path + ": not valid JSON: " + excerpt(error.what()));  // nlohmann quotes the whole token
  }
  if (!document.is_object()) throw SpidarGeometryError(path + ": must be a JSON object");
  static const char* const kKeys[] = {"frame_side_m",  "centre_m",      "metres_per_count",
                                      "tension_min_N", "tension_max_N", "max_force_N"};
  for (const auto& [key, value] : document.items()) {
    bool known = false;
    for (const char* name : kKeys) known = known || key == name;
    if (!known) fail(path, excerpt(key, 80), "unknown key (known: frame_side_m, centre_m, metres_per_count, tension_min_N, "
                                "tension_max_N, max_force_N)");
  }
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
  if (document.contains("centre_m")) {
    const nlohmann::json& centre = document.at("centre_m");
    if (!centre.is_array() || centre.size() != 3) fail(path, "centre_m", "must be [x, y, z] in metres");
    for (int a = 0; a < 3; ++a) {
      if (!centre[a].is_number() || !(std::abs(centre[a].get<double>()) <= kMaxFrameSide_m)) {
        fail(path, "centre_m", "must hold three numbers within ±" + readable(kMaxFrameSide_m) + " m, got " +
                                   quote_json(centre[a]));
      }
      geometry.centre_m[a] = centre[a].get<double>();
    }
  }
  if (!(geometry.tension_min_N < geometry.tension_max_N)) {
    fail(path, "tension_max_N", "must exceed tension_min_N (" + std::to_string(geometry.tension_min_N) + " N)");
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
