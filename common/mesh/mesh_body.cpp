// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mesh_body.h"

#include "common/mesh/mass_properties.h"
#include "common/mesh/mesh_check.h"
#include "common/mesh/mesh_file.h"
#include "common/runtime/input_error.h"

#include <algorithm>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

namespace impetus {
namespace {

// The body's origin in the file's frame: the centre of mass of a closed mesh, the centre of an open one's box.
Eigen::Vector3d body_origin(const TriangleMesh& mesh, bool closed) {
  if (closed) return mass_properties(mesh, 1.0).centre_of_mass_m;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices_m) box.extend(v);
  return box.center();
}

TriangleMesh moved_by(TriangleMesh mesh, const Eigen::Vector3d& offset_m) {
  for (Eigen::Vector3d& v : mesh.vertices_m) v += offset_m;
  return mesh;
}

}  // namespace

const MeshBody& MeshBody::load(const std::string& path, const Eigen::Vector3d& scale, bool dynamic) {
  // Read once per file, scale and use: a scene with many copies of one object, or Python running trial after
  // trial, does not read and build it again. Bodies stay for the process's life (the registry points at them).
  static std::mutex mutex;
  static std::map<std::tuple<std::string, double, double, double, bool>, std::unique_ptr<MeshBody>> loaded;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(path, scale.x(), scale.y(), scale.z(), dynamic);
  if (const auto found = loaded.find(key); found != loaded.end()) return *found->second;

  TriangleMesh mesh = load_mesh(path, scale);
  bool flipped = false;
  const MeshReport report = require_usable(mesh, dynamic, path, flipped);
  auto body = std::unique_ptr<MeshBody>(new MeshBody(std::move(mesh), report.closed(), flipped));
  register_mesh_geometry(body->shape_.mesh_hash, body.get());
  return *loaded.emplace(key, std::move(body)).first->second;
}

MeshBody::MeshBody(TriangleMesh mesh, bool closed, bool flipped)
    : origin_in_file_m_(body_origin(mesh, closed)),
      closed_(closed),
      flipped_(flipped),
      bvh_(moved_by(std::move(mesh), -origin_in_file_m_)) {
  const TriangleMesh& placed = bvh_.mesh();
  if (closed_) {
    const MassProperties unit = mass_properties(placed, 1.0);  // 1 kg/m³: the mass is the volume
    volume_m3_ = unit.volume_m3;
    inertia_per_kg_ = unit.inertia_about_com_kgm2 / unit.mass_kg;
  }
  Eigen::AlignedBox3d box;
  double radius_m = 0.0;
  for (const Eigen::Vector3d& v : placed.vertices_m) {
    box.extend(v);
    radius_m = std::max(radius_m, v.norm());
  }
  shape_.kind = ShapeKind::mesh;
  shape_.box_size_m = to_vec3(box.sizes());
  shape_.radius_m = radius_m;
  shape_.mesh_hash = mesh_hash(placed);
  if (shape_.mesh_hash == 0) shape_.mesh_hash = 1;  // 0 means "no mesh" on the link; FNV-1a gives it 1 in 2^64
  take_contact_features();
}

void MeshBody::take_contact_features() {
  // Two convex bodies touch where a corner of one meets the other or an edge of each crosses (shape.h), so a convex
  // mesh's corners and edges stand for it. An edge between two triangles of one flat face (a quad cut in two) is no
  // edge of the body: their normals agree to rounding (1e-12 in the cosine is 1.4 µrad, far below any bend a mesh is
  // built with).
  constexpr double kFlatCosine = 1.0 - 1e-12;
  const TriangleMesh& mesh = bvh_.mesh();
  if (!convex() || mesh.vertices_m.size() > static_cast<std::size_t>(kMaxContactSamples)) return;
  const std::vector<Eigen::Vector3d> normals = face_normals(mesh);
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>> faces_of_edge;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.triangles[t][static_cast<std::size_t>(k)];
      const std::uint32_t b = mesh.triangles[t][static_cast<std::size_t>((k + 1) % 3)];
      faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  }
  ContactEdges edges{};
  int edge_count = 0;
  for (const auto& [edge, faces] : faces_of_edge) {
    if (faces.size() != 2) return;  // convex() means closed: never
    const Eigen::Vector3d& face_a = normals[faces[0]];
    const Eigen::Vector3d& face_b = normals[faces[1]];
    if (face_a.dot(face_b) > kFlatCosine) continue;
    if (edge_count == kMaxContactEdges) return;  // more sharp edges than a contact list holds: no features
    edges[static_cast<std::size_t>(edge_count++)] = {mesh.vertices_m[edge.first], mesh.vertices_m[edge.second], 0.0,
                                                      face_a, face_b};
  }
  for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v) samples_[v] = {mesh.vertices_m[v], 0.0};
  sample_count_ = static_cast<int>(mesh.vertices_m.size());
  edges_ = edges;
  edge_count_ = edge_count;
}

int MeshBody::contact_samples(ContactSamples& samples) const {
  std::copy_n(samples_.begin(), sample_count_, samples.begin());
  return sample_count_;
}

int MeshBody::contact_edges(ContactEdges& edges) const {
  std::copy_n(edges_.begin(), edge_count_, edges.begin());
  return edge_count_;
}

SurfacePoint MeshBody::nearest(const Eigen::Vector3d& query_m) const {
  // The servo asks at the proxy every tick, which moves little: the walk starts from this thread's last answer on
  // this mesh (MeshBvh::nearest_from: the same answer, most boxes skipped at once). One hint per thread, so any
  // number of threads may ask; one that alternates between meshes only loses the head start.
  thread_local const MeshBody* last_body = nullptr;
  thread_local MeshPoint last{};
  MeshPoint point;
  const bool found = last_body == this ? bvh_.nearest_from(query_m, last, point) : bvh_.nearest(query_m, point);
  if (!found) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0};
  last_body = this;
  last = point;
  return {point.point_m, point.normal, point.signed_distance_m};
}

double MeshBody::support(const Eigen::Vector3d& normal) const {
  double best = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : bvh_.mesh().vertices_m) best = std::max(best, normal.dot(v));
  return best;
}

bool MeshBody::segment_enters(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) const {
  if (nearest(a).signed_distance_m < -margin_m || nearest(a + d).signed_distance_m < -margin_m) return true;
  const double length_m = d.norm();
  return length_m > margin_m && bvh_.segment_crosses(a, a + d, margin_m / length_m);
}

Eigen::Vector3d MeshBody::bounds_half(const Eigen::Matrix3d& rotation) const {
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : bvh_.mesh().vertices_m) half = half.cwiseMax((rotation * v).cwiseAbs());
  return half;
}

const SmoothSurface& MeshBody::smooth_surface() const {
  std::call_once(smooth_built_, [this] { smooth_ = std::make_unique<SmoothSurface>(bvh_.mesh()); });
  return *smooth_;
}

}  // namespace impetus
