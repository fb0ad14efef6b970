// SPDX-License-Identifier: Apache-2.0
#pragma once
// The state of one scene object at the end of a world step, in the world frame. The World refreshes it from ODE after
// every step; the feature extractor, the log and the tests read it without touching ODE.

#include "common/shape/shape.h"

#include <Eigen/Core>

namespace impetus {

struct ObjectState {
  BodyPose pose;  // position of the centre of mass and orientation body → world
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();  // world frame
  // The mean acceleration over the last world step, Δv/T_w (zero before the first step and for a body that did not
  // move in it): the second-order term of where the body will be (feature_extractor.h, reach).
  Eigen::Vector3d acceleration_mps2 = Eigen::Vector3d::Zero();
  // Zero for static objects (infinite mass), so the same formulas work for both.
  double inverse_mass_per_kg = 0.0;
  Eigen::Matrix3d inverse_inertia_world = Eigen::Matrix3d::Zero();  // about the centre of mass, 1/(kg·m²)
};

}  // namespace impetus
