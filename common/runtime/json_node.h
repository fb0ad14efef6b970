// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading a JSON input file (a scene, a shape's keys) so that every error names the file, the field by its JSON
// pointer (RFC 6901) and the value: `FILE: /objects/2/radius_m: must be positive (got -1)`.
//
// Quotes of user values stay short whatever the input (a file may hold a 50 MB token or 10^6 nested arrays), and
// are built without recursion.

#include "common/runtime/input_error.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

namespace impetus {

// Longest quote of a value or a key in a message: enough to find it in the file.
inline constexpr std::size_t kMaxQuotedChars = 80;

// The JSON document of the scene file at `path`, for a process that reads only part of it (the haptic controller's
// meshes and tool, the viewer's). Throws InputError naming the file if it cannot be read or is not JSON.
nlohmann::json read_scene_document(const std::string& path);

// A short quote of a value for an error message: a scalar as written (at most kMaxQuotedChars), an array or object by
// its size. Dumping a container would recurse once per nesting level and could quote megabytes.
std::string quote_json(const nlohmann::json& value);

// A node of a document with its JSON pointer. Every check throws InputError naming `source`, the pointer and the value.
// Holds references: the document and `source` must outlive the node.
class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string pointer, const std::string& source)
      : value_(value), pointer_(std::move(pointer)), source_(source) {}

  const nlohmann::json& value() const { return value_; }
  const std::string& pointer() const { return pointer_; }
  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const std::string& reason) const;
  [[noreturn]] void fail_missing(std::string_view key, std::string_view hint = {}) const;

  bool has(std::string_view key) const { return value_.contains(key); }
  JsonNode child(std::string_view key) const;
  JsonNode element(std::size_t index) const;
  JsonNode required(std::string_view key) const;

  void expect_object() const;
  // Unknown keys are errors: a misspelt optional key would otherwise silently fall back to its default. Each list in
  // `allowed` is a group of known keys (e.g. an object's common keys and its shape's own).
  void expect_keys(std::initializer_list<std::span<const std::string_view>> allowed) const;
  void expect_keys(std::initializer_list<std::string_view> allowed) const;

  double number() const;  // finite
  double positive() const;
  double non_negative() const;
  double in_range(double lowest, double highest, const char* unit) const;
  double positive_up_to(double highest, const char* unit) const;
  std::array<double, 3> vector_up_to(double highest, const char* unit) const;  // Euclidean length at most `highest`
  double in_unit_interval() const;
  // Four numbers w, x, y, z of norm 1 within 1e-6 (a quaternion written with ~7 significant digits is unit to ~1e-7:
  // those pass, anything a normalisation would noticeably change does not).
  std::array<double, 4> unit_quaternion() const;
  int positive_int(int highest) const;
  bool boolean() const;
  std::string string() const;
  template <std::size_t N>
  std::array<double, N> numbers() const {
    if (!value_.is_array() || value_.size() != N) fail("expected an array of " + std::to_string(N) + " numbers");
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = element(i).number();
    return out;
  }

 private:
  std::string where() const { return pointer_.empty() ? std::string("/") : pointer_; }

  const nlohmann::json& value_;
  std::string pointer_;
  const std::string& source_;
};

}  // namespace impetus
