// SPDX-License-Identifier: Apache-2.0
#include "common/spidar/device_file.h"

#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>

namespace impetus::device_file {

std::string spec_file(const std::string& spec, const std::string& name, const std::string& message) {
  if (spec == name) return {};
  const std::string prefix = name + ":";
  if (spec.rfind(prefix, 0) != 0 || spec.size() == prefix.size()) {
    throw SpidarGeometryError(message + ", got '" + excerpt(spec, 80) + "'");
  }
  return spec.substr(prefix.size());
}

std::uint64_t hash_values(std::initializer_list<double> values) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (double value : values) {
    unsigned char bytes[sizeof(double)];
    std::memcpy(bytes, &value, sizeof bytes);
    for (unsigned char byte : bytes) hash = (hash ^ byte) * 0x100000001b3ull;
  }
  return hash;
}

void fail(const std::string& path, const std::string& key, const std::string& reason) {
  throw SpidarGeometryError(path + ": " + key + ": " + reason);
}

void tension_range(const std::string& path, double tension_min_N, double tension_max_N) {
  if (!(tension_min_N < tension_max_N)) {
    fail(path, "tension_max_N", "must exceed tension_min_N (" + readable(tension_min_N) + " N)");
  }
}

nlohmann::json read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SpidarGeometryError(path + ": cannot open the device file");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {  // parse errors, and numbers too large for a double
    throw SpidarGeometryError(path + ": not valid JSON: " + excerpt(error.what()));  // nlohmann quotes the whole token
  }
  if (!document.is_object()) throw SpidarGeometryError(path + ": must be a JSON object");
  return document;
}

void check_keys(const nlohmann::json& document, const std::string& path, std::initializer_list<const char*> known) {
  for (const auto& [key, value] : document.items()) {
    bool found = false;
    for (const char* name : known) found = found || key == name;
    if (found) continue;
    std::string list;
    for (const char* name : known) list += (list.empty() ? "" : ", ") + std::string(name);
    fail(path, excerpt(key, 80), "unknown key (known: " + list + ")");
  }
}

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

Vec3 point(const nlohmann::json& document, const std::string& path, const char* key, const Vec3& fallback,
           double bound_m) {
  if (!document.contains(key)) return fallback;
  const nlohmann::json& value = document.at(key);
  if (!value.is_array() || value.size() != 3) fail(path, key, "must be [x, y, z] in metres");
  Vec3 out{};
  for (std::size_t a = 0; a < 3; ++a) {
    if (!value[a].is_number() || !(std::abs(value[a].get<double>()) <= bound_m)) {
      fail(path, key, "must hold three numbers within ±" + readable(bound_m) + " m, got " + quote_json(value[a]));
    }
    out[a] = value[a].get<double>();
  }
  return out;
}

}  // namespace impetus::device_file
