// SPDX-License-Identifier: Apache-2.0
#pragma once
// Least squares over one to three independent unit normals, the columns of N (an active face, edge or corner): the
// coefficients c of the combination N·c whose components along the normals are `rhs`,
//     Nᵀ·N·c = rhs,   c = G⁻¹·rhs with G = NᵀN the Gram matrix;
// with rhs = Nᵀ·v, N·c is the projection of v onto the span of the normals. Used by the god-object's projection and
// by the sharing of the reaction among planes. Columns beyond `size` are ignored; allocation-free.

#include <Eigen/Core>
#include <Eigen/LU>

namespace impetus {

inline Eigen::Vector3d gram_solve(const Eigen::Matrix3d& normals, int size, const Eigen::Vector3d& rhs) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d gram = normals.transpose() * normals;
  if (size == 1) {
    c[0] = rhs[0] / gram(0, 0);
  } else if (size == 2) {
    c.head<2>() = gram.topLeftCorner<2, 2>().inverse() * rhs.head<2>();
  } else if (size == 3) {
    c = gram.inverse() * rhs;
  }
  return c;
}

}  // namespace impetus
