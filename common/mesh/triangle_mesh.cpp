// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/triangle_mesh.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>

namespace impetus {

std::uint64_t mesh_hash(const TriangleMesh& mesh) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  const auto mix = [&hash](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 0x100000001b3ull;
  };
  const std::uint64_t counts[2] = {mesh.vertices_m.size(), mesh.triangles.size()};
  mix(counts, sizeof counts);
  for (const Eigen::Vector3d& v : mesh.vertices_m) mix(v.data(), 3 * sizeof(double));
  for (const auto& t : mesh.triangles) mix(t.data(), sizeof t);
  return hash;
}

std::vector<Eigen::Vector3d> face_normals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices_m[tri[0]];
    const Eigen::Vector3d normal = (mesh.vertices_m[tri[1]] - a).cross(mesh.vertices_m[tri[2]] - a);
    normals[t] = normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized()) : Eigen::Vector3d::UnitZ();
  }
  return normals;
}

std::vector<Eigen::Vector3d> angle_weighted_normals(const TriangleMesh& mesh,
                                                    const std::vector<Eigen::Vector3d>& face_normals) {
  std::vector<Eigen::Vector3d> normals(mesh.vertices_m.size(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& corner = mesh.vertices_m[tri[k]];
      const Eigen::Vector3d u = mesh.vertices_m[tri[(k + 1) % 3]] - corner;
      const Eigen::Vector3d w = mesh.vertices_m[tri[(k + 2) % 3]] - corner;
      normals[tri[k]] += std::atan2(u.cross(w).norm(), u.dot(w)) * face_normals[t];
    }
  }
  for (Eigen::Vector3d& normal : normals) {
    if (normal.norm() > 0.0) normal.normalize();
  }
  return normals;
}

}  // namespace impetus
