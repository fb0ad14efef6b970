// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/device/web_hand_params.h"

#include "common/runtime/json_node.h"
#include "common/runtime/message_text.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace impetus {

WebHandParams load_web_hand(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the web hand file");
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(path + ": not valid JSON: " + excerpt(error.what()));
  }
  const JsonNode root(document, "", path);
  root.expect_object();
  root.expect_keys({"mass_kg", "hand_stiffness_Npm", "hand_damping_Nspm", "workspace_centre_m", "workspace_side_m",
                    "rest_m", "max_force_N", "max_target_speed_mps"});
  WebHandParams params;
  params.source = path;
  // Bounds with their reasons: a fingertip and hand of 10 kg is an arm; 10^5 N/m and 10^3 N·s/m are stiffer than any
  // human limb (~10^2–10^3 N/m); a workspace of 10 m is a room (kMaxTouchTarget_m); 1 kN is beyond any device a person
  // should hold; 10 m/s is faster than a hand can reach.
  if (root.has("mass_kg")) params.hand.mass_kg = root.child("mass_kg").positive_up_to(10.0, " kg");
  if (root.has("hand_stiffness_Npm")) {
    params.hand.hand_stiffness_Npm = root.child("hand_stiffness_Npm").positive_up_to(1e5, " N/m");
  }
  if (root.has("hand_damping_Nspm")) {
    params.hand.hand_damping_Nspm = root.child("hand_damping_Nspm").in_range(0.0, 1e3, " N·s/m");
  }
  if (root.has("workspace_side_m")) params.workspace_side_m = root.child("workspace_side_m").positive_up_to(10.0, " m");
  if (root.has("workspace_centre_m")) {
    params.workspace_centre_m = root.child("workspace_centre_m").vector_up_to(10.0, " m");
  }
  params.rest_m = params.workspace_centre_m;
  if (root.has("rest_m")) {
    const JsonNode rest = root.child("rest_m");
    params.rest_m = rest.vector_up_to(10.0, " m");
    const double half = 0.5 * params.workspace_side_m;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(params.rest_m[a] - params.workspace_centre_m[a]) > half) {
        rest.fail("must lie inside the workspace (a cube of side " + readable(params.workspace_side_m) +
                  " m about workspace_centre_m)");
      }
    }
  }
  if (root.has("max_force_N")) params.max_force_N = root.child("max_force_N").positive_up_to(1000.0, " N");
  if (root.has("max_target_speed_mps")) {
    params.max_target_speed_mps = root.child("max_target_speed_mps").positive_up_to(10.0, " m/s");
  }
  return params;
}

}  // namespace impetus
