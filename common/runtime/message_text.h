// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pieces of error messages that must stay short and readable whatever the input: numbers as a person writes them and
// quotes of user text capped in length (a file may hold a 100 MB token; a message must not).

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace impetus {

// "%g": 0.1, 10000, 1e+06, never 309 digits.
inline std::string readable(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

// At most `max_chars` of `text`, then how long the whole was.
inline std::string excerpt(std::string_view text, std::size_t max_chars = 160) {
  if (text.size() <= max_chars) return std::string(text);
  return std::string(text.substr(0, max_chars)) + "... (" + std::to_string(text.size()) + " characters)";
}

// The choices an error message offers: "a", "a or b", "a, b or c".
inline std::string one_of(const std::vector<std::string>& choices) {
  std::string text;
  for (std::size_t k = 0; k < choices.size(); ++k) {
    if (k > 0) text += k + 1 == choices.size() ? " or " : ", ";
    text += choices[k];
  }
  return text;
}

}  // namespace impetus
