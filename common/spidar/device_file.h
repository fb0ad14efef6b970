// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a device description file (JSON: the 4-string SPIDAR's, geometry.h; the grip SPIDAR's, grip_geometry.h):
// one object of known keys, each optional, each value within its bound. Every error is a SpidarGeometryError naming
// the file and the key, with the value quoted short.

#include "common/contract/vec3.h"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>

namespace impetus {

class SpidarGeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace device_file {

// Bounds every device file's values share: a string frame of 10 m is a room-sized SPIDAR; an encoder count above
// 1 cm cannot resolve a contact; 1 kN is beyond any string and motor a person should be tied to.
inline constexpr double kMaxFrameSide_m = 10.0;
inline constexpr double kMaxMetresPerCount = 0.01;
inline constexpr double kMaxForce_N = 1000.0;

// The file a device spec names: "" for `name` alone (the built-in device), FILE for "name:FILE"; throws for anything
// else, with `message` (what the spec must be) and the spec quoted.
std::string spec_file(const std::string& spec, const std::string& name, const std::string& message);

// FNV-1a over the values' bytes in their order: a device's hash of its values, not of its file's text.
std::uint64_t hash_values(std::initializer_list<double> values);

// The file's JSON object; throws for a file that cannot be read, is not JSON, or is not an object.
nlohmann::json read(const std::string& path);
// Throws for a key not in `known`, listing them.
void check_keys(const nlohmann::json& document, const std::string& path, std::initializer_list<const char*> known);
// The number under `key` in (0, highest], or `fallback` if there is none.
double positive(const nlohmann::json& document, const std::string& path, const char* key, double fallback,
                double highest);
// The point [x, y, z] under `key`, each within ±bound_m, or `fallback` if there is none.
Vec3 point(const nlohmann::json& document, const std::string& path, const char* key, const Vec3& fallback,
           double bound_m);
// Throws, naming tension_max_N, unless tension_min_N < tension_max_N: a string must be able to pull harder than its
// least tension.
void tension_range(const std::string& path, double tension_min_N, double tension_max_N);
[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& reason);

}  // namespace device_file
}  // namespace impetus
