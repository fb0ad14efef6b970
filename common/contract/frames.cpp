// SPDX-License-Identifier: Apache-2.0
#include "common/contract/frames.h"

namespace impetus {

const char* to_string(Coupling coupling) {
  switch (coupling) {
    case Coupling::impulse: return "impulse";
    case Coupling::position: return "position";
    case Coupling::local: return "local";
  }
  return "unknown";
}

}  // namespace impetus
