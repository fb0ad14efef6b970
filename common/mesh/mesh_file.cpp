// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mesh_file.h"

#include "common/runtime/input_error.h"
#include "common/runtime/message_text.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unordered_map>

namespace impetus {
namespace {

// Vertices are welded by their exact position: a file's vertices may repeat a position with other normals or
// texture coordinates (OBJ), or every triangle may have its own three (STL), and the edges are found through shared
// vertices (mesh_check.h). Welding nearby but unequal positions would change the user's geometry; that is left to
// their modelling tool, and an unwelded seam shows as an open edge.
struct PositionKey {
  std::uint64_t bits[3];
  bool operator==(const PositionKey& other) const { return std::memcmp(bits, other.bits, sizeof bits) == 0; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& key) const {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (std::uint64_t b : key.bits) h = (h ^ b) * 0x100000001b3ull;
    return static_cast<std::size_t>(h);
  }
};

}  // namespace

TriangleMesh load_mesh(const std::string& path, const Eigen::Vector3d& scale) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error) || !std::ifstream(path)) {
    throw InputError(path + ": cannot open the mesh file");
  }
  Assimp::Importer importer;
  // Points and lines are not surfaces: dropped, as are the meshes that held only them.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (scene == nullptr) {
    throw InputError(path + ": not a mesh file Assimp can read: " + excerpt(importer.GetErrorString()));
  }
  TriangleMesh mesh;
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> welded;
  std::size_t faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) faces += scene->mMeshes[m]->mNumFaces;
  if (faces > MeshLimits::kMaxTriangles) {
    throw InputError(path + ": " + std::to_string(faces) + " triangles, more than the " +
                     std::to_string(MeshLimits::kMaxTriangles) + " a mesh may have (docs/meshes.md)");
  }
  mesh.triangles.reserve(faces);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    std::vector<std::uint32_t> index(part.mNumVertices);
    for (unsigned v = 0; v < part.mNumVertices; ++v) {
      const aiVector3D& p = part.mVertices[v];
      const Eigen::Vector3d position(static_cast<double>(p.x) * scale.x(), static_cast<double>(p.y) * scale.y(),
                                     static_cast<double>(p.z) * scale.z());
      if (!position.allFinite() || position.cwiseAbs().maxCoeff() > MeshLimits::kMaxCoordinate_m) {
        throw InputError(path + ": vertex " + std::to_string(v + 1) + " of mesh " + std::to_string(m + 1) + " is (" +
                         readable(position.x()) + ", " + readable(position.y()) + ", " + readable(position.z()) +
                         ") m after scaling: coordinates must be finite and within ±" +
                         readable(MeshLimits::kMaxCoordinate_m) + " m (a file in millimetres needs \"scale\": 0.001)");
      }
      PositionKey key{};
      std::memcpy(key.bits, position.data(), sizeof key.bits);
      const auto [it, added] = welded.emplace(key, static_cast<std::uint32_t>(mesh.vertices_m.size()));
      if (added) mesh.vertices_m.push_back(position);
      index[v] = it->second;
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;  // triangulated: only stray points and lines are left, and were removed
      mesh.triangles.push_back({index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
    }
  }
  if (mesh.triangles.empty()) throw InputError(path + ": holds no triangles");
  // A negative scale on an odd number of axes mirrors the mesh and turns its winding inside out.
  if (scale.x() * scale.y() * scale.z() < 0.0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  }
  return mesh;
}

}  // namespace impetus
