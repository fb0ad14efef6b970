// SPDX-License-Identifier: Apache-2.0
#include "viewer/view_encoding.h"

#include "common/mesh/mesh_body.h"
#include "common/shape/mesh_geometry.h"
#include "common/shape/shape.h"
#include "viewer/mesh_coarsening.h"
#include "viewer/view_protocol.h"

#include <nlohmann/json.hpp>

#include <bit>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

namespace impetus::view {
namespace {

static_assert(std::endian::native == std::endian::little, "frame messages are little-endian float64 (view_protocol.h)");

// Appends float64 values to a byte string.
class Packer {
 public:
  explicit Packer(std::string& out) : out_(out) { out_.clear(); }
  void add(double value) {
    char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    out_.append(bytes, sizeof value);
  }
  void add(const Vec3& v) {
    for (double x : v) add(x);
  }

 private:
  std::string& out_;
};

// A mesh body's form for the page (view_protocol.h §1 "mesh"): its triangles when this process loaded the file (the
// registry has its hash), coarsened if they are too many to send; else why the page draws its bound instead.
nlohmann::json mesh_form(const Shape& shape) {
  const auto* body = dynamic_cast<const MeshBody*>(find_mesh_geometry(shape.mesh_hash));
  if (body == nullptr) return {{"drawn", "bound"}, {"why", "its file was not loaded (viewer --meshes-from SCENE)"}};
  // A finer mesh than a page is sent is sent coarsened to fit (mesh_coarsening.h).
  const CoarseMesh coarse = coarsened(body->bvh().mesh(), kMaxViewMeshTriangles);
  const TriangleMesh& mesh = coarse.mesh;
  // Micrometres are finer than a pixel of any view of a desk-sized scene, and keep the numbers short.
  constexpr double kVertexResolution_m = 1e-6;
  std::vector<double> vertices;
  vertices.reserve(3 * mesh.vertices_m.size());
  for (const Eigen::Vector3d& v : mesh.vertices_m) {
    for (int i = 0; i < 3; ++i) vertices.push_back(std::round(v[i] / kVertexResolution_m) * kVertexResolution_m);
  }
  std::vector<std::uint32_t> triangles;
  triangles.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.insert(triangles.end(), t.begin(), t.end());
  nlohmann::json form = {
      {"drawn", "triangles"}, {"vertices_m", std::move(vertices)}, {"triangles", std::move(triangles)}};
  if (coarse.cell_m > 0.0) {
    form["coarsened_from"] = body->bvh().mesh().triangles.size();
    form["cell_m"] = coarse.cell_m;
  }
  return form;
}

// A shape's fields for the page, as a body's (view_protocol.h §1).
void add_shape(const Shape& shape, nlohmann::json& entry) {
  entry["shape"] = to_string(shape.kind);
  entry["size_m"] = shape.box_size_m;
  entry["radius_m"] = shape.radius_m;
  entry["length_m"] = shape.length_m;
}

}  // namespace

std::string scene_message(const ViewScene& scene, const std::string& source, const std::optional<ReplayRange>& replay,
                          const ToolShape* tool) {
  nlohmann::json message = {{"type", "scene"},
                            {"mode", replay ? "replay" : "live"},
                            {"source", source},
                            {"coupling", to_string(scene.coupling)},
                            {"world_rate_hz", scene.world_rate_hz},
                            {"floor", {{"present", scene.floor_present != 0}, {"height_m", scene.floor_height_m}}}};
  nlohmann::json bodies = nlohmann::json::array();
  for (std::uint32_t k = 0; k < scene.body_count; ++k) {
    const ViewBodyInfo& body = scene.bodies[k];
    nlohmann::json entry = {{"name", std::string(body.name.data())},  // NUL-terminated (scene_problem checked)
                            {"dynamic", body.dynamic != 0}};
    add_shape(body.shape, entry);
    if (body.shape.kind == ShapeKind::mesh) {
      char hash[17];
      std::snprintf(hash, sizeof hash, "%016" PRIx64, body.shape.mesh_hash);
      entry["mesh_hash"] = hash;
      entry["mesh"] = mesh_form(body.shape);
    }
    bodies.push_back(std::move(entry));
  }
  message["bodies"] = std::move(bodies);
  if (tool != nullptr) {
    nlohmann::json entry = nlohmann::json::object();
    add_shape(tool->shape, entry);
    if (tool->shape.kind == ShapeKind::mesh) entry["mesh"] = mesh_form(tool->shape);  // drawn as a body's mesh is
    const Eigen::Vector3d& p = tool->placement.position_m;
    const Eigen::Quaterniond& q = tool->placement.orientation;
    entry["placement"] = {{"position_m", {p.x(), p.y(), p.z()}}, {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
    message["tool"] = std::move(entry);
  }
  if (replay) {
    message["replay"] = {{"start_s", replay->start_s}, {"end_s", replay->end_s}, {"frame_count", replay->frame_count}};
  }
  // Names come from scene files and may hold any bytes: replace invalid UTF-8 rather than fail.
  return message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void encode_frame(const WorldSnapshot& snapshot, bool playing, double speed, std::string& out,
                  const ViewToolFrame* tool) {
  Packer pack(out);
  const double lateness_p99_s = snapshot.haptic_stats.lateness_p99_ns > 0
                                    ? static_cast<double>(snapshot.haptic_stats.lateness_p99_ns) * 1e-9
                                    : std::numeric_limits<double>::quiet_NaN();
  const double header[kFrameHeaderValues] = {static_cast<double>(kFrameKind),
                                             static_cast<double>(snapshot.frame_index),
                                             snapshot.world_time_s,
                                             snapshot.world_period_s,
                                             static_cast<double>(snapshot.body_count),
                                             static_cast<double>(snapshot.endpoint_count),
                                             lateness_p99_s,
                                             static_cast<double>(snapshot.haptic_stats.faults),
                                             static_cast<double>(snapshot.world_stats.skipped_periods),
                                             static_cast<double>(snapshot.haptic_stats.skipped_periods),
                                             playing ? 1.0 : 0.0,
                                             speed,
                                             snapshot.dent.object_id >= 0 ? 1.0 : 0.0,
                                             tool != nullptr ? 1.0 : 0.0,
                                             0.0, 0.0};
  for (double value : header) pack.add(value);
  for (std::uint32_t k = 0; k < snapshot.body_count; ++k) {
    const ViewBodyPose& body = snapshot.bodies[k];
    pack.add(body.position_m);
    for (double q : body.orientation_wxyz) pack.add(q);
  }
  for (std::uint32_t e = 0; e < snapshot.endpoint_count; ++e) {
    const ViewEndpoint& endpoint = snapshot.endpoints[e];
    pack.add(static_cast<double>(endpoint.endpoint));
    pack.add(endpoint.finger_valid != 0 ? 1.0 : 0.0);
    pack.add(endpoint.finger_m);
    pack.add(endpoint.proxy_m);
    pack.add(endpoint.force_N);
    pack.add(static_cast<double>(endpoint.plane_count));
    for (std::uint32_t p = 0; p < endpoint.plane_count; ++p) {
      pack.add(endpoint.planes[p].point_m);
      pack.add(endpoint.planes[p].normal);
    }
  }
  const ViewDent& dent = snapshot.dent;
  if (dent.object_id >= 0) {
    const double values[kDentValues] = {static_cast<double>(dent.object_id), static_cast<double>(dent.version),
                                        static_cast<double>(dent.columns),   static_cast<double>(dent.rows),
                                        dent.x0_m, dent.y0_m, dent.dx_m, dent.dy_m};
    for (double value : values) pack.add(value);
    for (std::uint32_t k = 0; k < dent.columns * dent.rows; ++k) pack.add(static_cast<double>(dent.depth_m[k]));
  }
  if (tool != nullptr) {
    pack.add(tool->valid ? 1.0 : 0.0);
    for (const ViewBodyPose* pose : {&tool->grip, &tool->proxy}) {
      pack.add(pose->position_m);
      for (double q : pose->orientation_wxyz) pack.add(q);
    }
    pack.add(tool->force_N);
    pack.add(tool->torque_Nm);
  }
}

}  // namespace impetus::view
