// SPDX-License-Identifier: Apache-2.0
#include "common/runtime/json_node.h"

#include "common/runtime/message_text.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace impetus {
namespace {

// JSON pointer escaping (RFC 6901) for keys that contain '/' or '~'.
std::string escape_key(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::string quote_json(const nlohmann::json& value) {
  if (value.is_array()) return "an array of " + std::to_string(value.size()) + " elements";
  if (value.is_object()) return "an object with " + std::to_string(value.size()) + " keys";
  return excerpt(value.dump(), kMaxQuotedChars);
}

void JsonNode::fail(const std::string& reason) const {
  throw InputError(source_ + ": " + where() + ": " + reason + " (got " + quote_json(value_) + ")");
}

void JsonNode::fail_missing(std::string_view key, std::string_view hint) const {
  std::string message = source_ + ": " + pointer_ + "/" + escape_key(key) + ": missing required field";
  if (!hint.empty()) message += std::string(" (") + std::string(hint) + ")";
  throw InputError(message);
}

JsonNode JsonNode::child(std::string_view key) const {
  return JsonNode(value_.at(std::string(key)), pointer_ + "/" + escape_key(key), source_);
}

JsonNode JsonNode::element(std::size_t index) const {
  return JsonNode(value_.at(index), pointer_ + "/" + std::to_string(index), source_);
}

JsonNode JsonNode::required(std::string_view key) const {
  if (!has(key)) fail_missing(key);
  return child(key);
}

void JsonNode::expect_object() const {
  if (!value_.is_object()) fail("expected an object");
}

void JsonNode::expect_keys(std::initializer_list<std::span<const std::string_view>> allowed) const {
  expect_object();
  for (const auto& item : value_.items()) {
    bool known = false;
    for (const std::span<const std::string_view> group : allowed) {
      for (std::string_view name : group) known = known || item.key() == name;
    }
    if (!known) {
      const std::string key = excerpt(item.key(), kMaxQuotedChars);
      throw InputError(source_ + ": " + pointer_ + "/" + escape_key(key) + ": unknown key '" + key + "' (got " +
                       quote_json(item.value()) + ")");
    }
  }
}

void JsonNode::expect_keys(std::initializer_list<std::string_view> allowed) const {
  expect_keys({std::span<const std::string_view>(allowed.begin(), allowed.size())});
}

double JsonNode::number() const {
  if (!value_.is_number()) fail("expected a number");
  const double x = value_.get<double>();
  if (!std::isfinite(x)) fail("expected a finite number");
  return x;
}

double JsonNode::positive() const {
  const double x = number();
  if (!(x > 0.0)) fail("must be positive");
  return x;
}

double JsonNode::non_negative() const {
  const double x = number();
  if (x < 0.0) fail("must not be negative");
  return x;
}

double JsonNode::in_range(double lowest, double highest, const char* unit) const {
  const double x = number();
  if (x < lowest || x > highest) fail("must be between " + readable(lowest) + " and " + readable(highest) + unit);
  return x;
}

double JsonNode::positive_up_to(double highest, const char* unit) const {
  const double x = positive();
  if (x > highest) fail("must be at most " + readable(highest) + unit);
  return x;
}

std::array<double, 3> JsonNode::vector_up_to(double highest, const char* unit) const {
  const std::array<double, 3> v = numbers<3>();
  if (std::hypot(v[0], v[1], v[2]) > highest) fail("its length must be at most " + readable(highest) + unit);
  return v;
}

double JsonNode::in_unit_interval() const {
  const double x = number();
  if (x < 0.0 || x > 1.0) fail("must be in [0, 1]");
  return x;
}

nlohmann::json read_scene_document(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open scene file");
  std::stringstream text;
  text << file.rdbuf();
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& error) {
    throw InputError(path + ": not JSON: " + excerpt(error.what()));
  }
}

std::array<double, 4> JsonNode::unit_quaternion() const {
  constexpr double kTolerance = 1e-6;
  const std::array<double, 4> q = numbers<4>();
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > kTolerance) {
    fail("quaternion must be unit within 1e-6 (norm " + std::to_string(norm) + ")");
  }
  return q;
}

int JsonNode::positive_int(int highest) const {
  if (!value_.is_number_integer()) fail("expected a whole number");
  // Compared as a double first: a huge integer must not wrap when converted.
  if (value_.get<double>() < 1.0 || value_.get<double>() > highest) {
    fail("must be a whole number from 1 to " + std::to_string(highest));
  }
  return static_cast<int>(value_.get<std::int64_t>());
}

bool JsonNode::boolean() const {
  if (!value_.is_boolean()) fail("expected true or false");
  return value_.get<bool>();
}

std::string JsonNode::string() const {
  if (!value_.is_string()) fail("expected a string");
  return value_.get<std::string>();
}

}  // namespace impetus
