// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a user or a script needs to know before a trial has run, from the code that decides it: the couplings,
// engines and shape kinds there are, the haptic rate, and what a scene's left-out keys become. `world_manager
// --defaults` prints it and Python's impetus.defaults() returns it, so no script copies a C++ default by hand.

#include <nlohmann/json.hpp>

namespace impetus {

// {"couplings": [...], "engines": [...], "shapes": [...], "haptic_rate_hz": 1000,
//  "scene": {"gravity_mps2", "friction", "restitution", "physics": {...}, "haptic": {...}}}: the last is what
// parse_scene gives a scene with no keys but "objects".
nlohmann::json defaults_document();

}  // namespace impetus
