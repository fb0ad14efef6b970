// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/deformable_material.h"

#include <cmath>

namespace impetus {

const char* to_string(DeformableMaterial::Rule rule) {
  return rule == DeformableMaterial::Rule::penetration ? "penetration" : "impulse";
}

const char* to_string(DeformableMaterial::Law law) {
  return law == DeformableMaterial::Law::elastic ? "elastic" : "plastic";
}

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

double DeformableMaterial::yield_force_N() const {
  if (rule != Rule::impulse || law != Law::plastic) return 0.0;
  return yield_stress_Pa * kPi * contact_radius_m * contact_radius_m;
}

double DeformableMaterial::yield_depth_mpNs() const {
  if (rule != Rule::impulse || law != Law::plastic) return 0.0;
  return 2.0 / (kPi * contact_radius_m * contact_radius_m * flow_resistance_Paspm);
}

double DeformableMaterial::highest_frequency_radps(double cell_x_m, double cell_y_m) const {
  const double laplacian_pm2 = 4.0 / (cell_x_m * cell_x_m) + 4.0 / (cell_y_m * cell_y_m);
  return std::sqrt((stiffness_Papm + tension_Npm * laplacian_pm2) / areal_density_kgpm2);
}

}  // namespace impetus
