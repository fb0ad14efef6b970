// SPDX-License-Identifier: Apache-2.0
#pragma once
// ASCII case folding for names compared without regard to case (flag values, host names). Not for other text: it
// leaves every byte outside A–Z as it is.

#include <string>
#include <string_view>

namespace impetus {

inline std::string ascii_lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

}  // namespace impetus
