// SPDX-License-Identifier: Apache-2.0
#include "world_manager/impulse_limits.h"

namespace impetus {

LightObjects light_for_impulse_coupling(const Scene& scene, double world_period_s, double max_force_N) {
  LightObjects out;
  for (const SceneObject& object : scene.objects) {
    if (!object.dynamic || !(object.mass_kg > 0.0)) continue;
    const double speed_mps = max_force_N * world_period_s / object.mass_kg;
    if (!(speed_mps > kHandSpeed_mps)) continue;
    ++out.count;
    if (out.count == 1 || object.mass_kg < out.lightest_mass_kg) {
      out.lightest_name = object.name;
      out.lightest_mass_kg = object.mass_kg;
      out.lightest_speed_mps = speed_mps;
    }
  }
  return out;
}

}  // namespace impetus
