// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/plastic_material.h"

namespace impetus {

const char* to_string(PlasticMaterial::Rule rule) {
  return rule == PlasticMaterial::Rule::penetration ? "penetration" : "impulse";
}

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

double PlasticMaterial::yield_force_N() const {
  return rule == Rule::impulse ? yield_stress_Pa * kPi * contact_radius_m * contact_radius_m : 0.0;
}

double PlasticMaterial::yield_depth_mpNs() const {
  return rule == Rule::impulse ? 2.0 / (kPi * contact_radius_m * contact_radius_m * flow_resistance_Paspm) : 0.0;
}

}  // namespace impetus
