// SPDX-License-Identifier: Apache-2.0
#pragma once
// The error every input reader throws (scene files, shapes' keys): its message names the file, the field and the value.

#include <stdexcept>

namespace impetus {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace impetus
