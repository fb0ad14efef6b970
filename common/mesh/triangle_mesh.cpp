// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/triangle_mesh.h"

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

}  // namespace impetus
