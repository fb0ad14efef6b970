// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/smooth_surface.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// Phong tessellation's shape factor: 1/2 puts a tessellated sphere's points back on it to fourth order (header).
constexpr double kShape = 0.5;

}  // namespace

SmoothSurface::SmoothSurface(const TriangleMesh& mesh)
    : vertices_m_(mesh.vertices_m.begin(), mesh.vertices_m.end()),
      triangles_(mesh.triangles.begin(), mesh.triangles.end()) {
  const std::vector<Eigen::Vector3d> faces = face_normals(mesh);
  normals_ = angle_weighted_normals(mesh, faces);
  // Each vertex's triangles, by counting then filling.
  ring_begin_.assign(vertices_m_.size() + 1, 0);
  for (const auto& tri : triangles_) {
    for (std::uint32_t v : tri) ++ring_begin_[v + 1];
  }
  for (std::size_t v = 0; v < vertices_m_.size(); ++v) ring_begin_[v + 1] += ring_begin_[v];
  ring_.resize(ring_begin_.back());
  std::vector<std::uint32_t> filled(ring_begin_.begin(), ring_begin_.end() - 1);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    for (std::uint32_t v : triangles_[t]) ring_[filled[v]++] = t;
  }
  // The crease at each edge: the angle between the normals of its two triangles, the other found around the edge's
  // first vertex.
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
      longest_edge_m_ = std::max(longest_edge_m_, (vertices_m_[b] - vertices_m_[a]).norm());
      for (std::uint32_t i = ring_begin_[a]; i < ring_begin_[a + 1]; ++i) {
        const std::uint32_t other = ring_[i];
        const auto& o = triangles_[other];
        if (other == t || std::find(o.begin(), o.end(), b) == o.end()) continue;
        const double angle = std::atan2(faces[t].cross(faces[other]).norm(), faces[t].dot(faces[other]));
        if (angle > largest_crease_rad_) {
          largest_crease_rad_ = angle;
          largest_crease_triangle_ = t;
        }
      }
    }
  }
}

double SmoothSurface::farthest_on(std::uint32_t t, const Eigen::Vector3d& direction, Eigen::Vector3d& b_out) const {
  // With q = Σ b_i v_i, d·p(b) = Σ_j b_j (d·v_j + α c_j s_j) − α Σ_i Σ_j b_i c_i M_ij b_j, where c_i = n_i·d,
  // s_i = v_i·n_i and M_ij = v_j·n_i: a quadratic in b. With b = (1 − u − w, u, w) it is a quadratic in (u, w) over
  // the triangle u, w ≥ 0, u + w ≤ 1, whose largest value is at its stationary point inside, on an edge's, or at a
  // corner.
  const auto& tri = triangles_[t];
  Eigen::Vector3d linear;
  Eigen::Matrix3d quadratic;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& n = normals_[tri[i]];
    const double c = n.dot(direction);
    linear[i] = direction.dot(vertices_m_[tri[i]]) + kShape * c * n.dot(vertices_m_[tri[i]]);
    for (int j = 0; j < 3; ++j) quadratic(i, j) = kShape * c * n.dot(vertices_m_[tri[j]]);
  }
  const Eigen::Matrix3d symmetric = 0.5 * (quadratic + quadratic.transpose());
  const auto value = [&](const Eigen::Vector3d& b) { return linear.dot(b) - b.dot(symmetric * b); };
  // b = b0 + E·(u, w): its gradient in (u, w) is Eᵀ(linear − 2·S·b).
  Eigen::Matrix<double, 3, 2> along;
  along << -1.0, -1.0, 1.0, 0.0, 0.0, 1.0;
  const Eigen::Vector3d corner0(1.0, 0.0, 0.0);
  double best = -std::numeric_limits<double>::infinity();
  const auto consider = [&](const Eigen::Vector3d& b) {
    const double v = value(b);
    if (v > best) {
      best = v;
      b_out = b;
    }
  };
  for (int k = 0; k < 3; ++k) consider(Eigen::Vector3d::Unit(k));
  // Each edge from corner i to corner j: b = e_i + s (e_j − e_i), a quadratic in s on [0, 1].
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d from = Eigen::Vector3d::Unit(i), step = Eigen::Vector3d::Unit((i + 1) % 3) - from;
    const double slope = linear.dot(step) - 2.0 * from.dot(symmetric * step);
    const double curve = step.dot(symmetric * step);  // value = v(from) + slope·s − curve·s²
    if (curve > 0.0) {
      const double s_best = 0.5 * slope / curve;
      if (s_best > 0.0 && s_best < 1.0) consider(from + s_best * step);
    }
  }
  const Eigen::Matrix2d hessian = 2.0 * along.transpose() * symmetric * along;  // of −value: positive if concave
  const Eigen::Vector2d gradient0 = along.transpose() * (linear - 2.0 * symmetric * corner0);
  if (hessian.determinant() > 0.0 && hessian(0, 0) > 0.0) {
    const Eigen::Vector2d uw = hessian.inverse() * gradient0;
    if (uw[0] > 0.0 && uw[1] > 0.0 && uw[0] + uw[1] < 1.0) consider(corner0 + along * uw);
  }
  return best;
}

SmoothPoint SmoothSurface::point_at(std::uint32_t t, const Eigen::Vector3d& b) const {
  const auto& tri = triangles_[t];
  Eigen::Vector3d flat = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    flat += b[k] * vertices_m_[tri[k]];
    normal += b[k] * normals_[tri[k]];
  }
  // q + α Σ b_i ((v_i − q)·n_i) n_i: the flat point moved toward each vertex's tangent plane.
  Eigen::Vector3d lift = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& n = normals_[tri[k]];
    lift += b[k] * (vertices_m_[tri[k]] - flat).dot(n) * n;
  }
  SmoothPoint out;
  out.point_m = flat + kShape * lift;
  out.normal = normal.normalized();
  return out;
}

SmoothPoint SmoothSurface::farthest(const Eigen::Vector3d& direction, std::uint32_t start) const {
  SmoothPoint out;
  if (vertices_m_.empty()) return out;
  std::uint32_t v = start < vertices_m_.size() ? start : 0;
  // The climb: to the neighbour farthest along the direction while one is farther (strictly, so it ends).
  for (;;) {
    std::uint32_t best = v;
    double best_height = direction.dot(vertices_m_[v]);
    for (std::uint32_t i = ring_begin_[v]; i < ring_begin_[v + 1]; ++i) {
      for (std::uint32_t w : triangles_[ring_[i]]) {
        const double height = direction.dot(vertices_m_[w]);
        if (height > best_height) {
          best = w;
          best_height = height;
        }
      }
    }
    if (best == v) break;
    v = best;
  }
  // The surface's farthest point lies on a triangle around that vertex, or around a neighbour of it where the
  // triangles are uneven: the largest of each one's own largest.
  double best = -std::numeric_limits<double>::infinity();
  std::uint32_t best_triangle = 0;
  Eigen::Vector3d best_b(1.0, 0.0, 0.0);
  for (std::uint32_t i = ring_begin_[v]; i < ring_begin_[v + 1]; ++i) {
    for (std::uint32_t w : triangles_[ring_[i]]) {
      for (std::uint32_t j = ring_begin_[w]; j < ring_begin_[w + 1]; ++j) {
        Eigen::Vector3d b;
        const double height = farthest_on(ring_[j], direction, b);
        if (height > best) {
          best = height;
          best_triangle = ring_[j];
          best_b = b;
        }
      }
    }
  }
  out = point_at(best_triangle, best_b);
  out.vertex = v;
  return out;
}

}  // namespace impetus
