// SPDX-License-Identifier: Apache-2.0
#pragma once
// Plain 3-vectors for structs that cross process boundaries, and their bridge to Eigen.
//
// Eigen's fixed-size types are not trivially copyable (they declare copy constructors), so anything placed in shared
// memory uses Vec3 = std::array<double, 3>; code converts at the boundary and computes with Eigen.

#include <Eigen/Core>

#include <array>
#include <cmath>

namespace impetus {

using Vec3 = std::array<double, 3>;

inline Eigen::Vector3d to_eigen(const Vec3& v) { return {v[0], v[1], v[2]}; }
inline Vec3 to_vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

inline bool all_finite(const Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace impetus
