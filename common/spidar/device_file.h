// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a device description file (JSON: the 4-string SPIDAR's, geometry.h; the grip SPIDAR's, grip_geometry.h):
// one object of known keys, each optional, each value within its bound. Every error is a SpidarGeometryError naming
// the file and the key, with the value quoted short.

#include "common/contract/vec3.h"

#include <nlohmann/json_fwd.hpp>

#include <initializer_list>
#include <stdexcept>
#include <string>

namespace impetus {

class SpidarGeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace device_file {

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
[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& reason);

}  // namespace device_file
}  // namespace impetus
