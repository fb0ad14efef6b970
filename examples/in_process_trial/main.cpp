// SPDX-License-Identifier: Apache-2.0
// A custom scene and an in-process trial against an installed Impetus: a 0.5 kg puck on a low-friction table is
// tapped by the simulated finger; prints how far it slid and the impulse the world applied. No process is started.

#include "loop/in_process_trial.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : std::filesystem::temp_directory_path();
  const std::filesystem::path scene = dir / "puck.json";
  // The finger's tap starts near the origin moving along +x at 25 mm height; the puck's -x side waits 5 mm ahead.
  std::ofstream(scene) << R"({
    "description": "A 0.5 kg puck (cylinder, 4 cm radius, 5 cm tall) on a table with PTFE-like friction",
    "floor": {"static_friction": 0.08, "dynamic_friction": 0.06},
    "objects": [{"name": "puck", "shape": "cylinder", "radius_m": 0.04, "length_m": 0.05, "dynamic": true,
                 "mass_kg": 0.5, "position_m": [0.045, 0.0, 0.025], "static_friction": 0.08,
                 "dynamic_friction": 0.06}]
  })";

  impetus::InProcessTrialOptions options;
  options.scene_path = scene.string();
  options.trajectory = "tap";
  options.coupling = impetus::Coupling::local;
  try {
    const nlohmann::json summary = impetus::run_in_process_trial(options);
    const auto& puck = summary["objects"]["puck"];
    const double travel_m = puck["position"][0].get<double>() - 0.045;
    std::printf("puck slid %.3f m; impulse applied %.4f N·s along x; %llu haptic ticks\n", travel_m,
                puck["impulse_Ns"][0].get<double>(), summary["haptic"]["ticks"].get<unsigned long long>());
    return travel_m > 0.0 ? 0 : 1;  // a tap that struck the puck moved it along +x
  } catch (const std::exception& error) {
    std::fprintf(stderr, "in_process_trial: %s\n", error.what());
    return 1;
  }
}
