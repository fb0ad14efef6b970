// SPDX-License-Identifier: Apache-2.0
#pragma once
// Orientations for tests that must hold in every orientation: the 24 turns that map the axes onto the axes (a box's
// symmetries; each puts a different body axis first, where ties between axes are broken), then `random_count` random
// turns from `seed`, under which coordinates meant to coincide agree only to rounding.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace impetus::test {

inline std::vector<Eigen::Quaterniond> axis_and_random_turns(int random_count, unsigned seed) {
  std::vector<Eigen::Quaterniond> turns;
  const std::array<Eigen::Vector3d, 6> axes{Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                            Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY(),
                                            Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  for (const Eigen::Vector3d& x : axes) {
    for (const Eigen::Vector3d& y : axes) {
      if (std::abs(x.dot(y)) > 0.5) continue;
      Eigen::Matrix3d m;
      m << x, y, x.cross(y);
      turns.emplace_back(m);
    }
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < random_count; ++k) {
    turns.push_back(Eigen::Quaterniond(unit(rng), unit(rng), unit(rng), unit(rng)).normalized());
  }
  return turns;
}

}  // namespace impetus::test
