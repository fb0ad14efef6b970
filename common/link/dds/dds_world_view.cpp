// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_world_view.h"

#include "common/link/dds/dds_codec.h"
#include "common/link/dds/dds_entities.h"
#include "common/runtime/process.h"

#include <dds/dds.h>

#include <algorithm>
#include <cstring>

namespace impetus {
namespace {

constexpr const char* kSceneTopic = "impetus_view_scene";
constexpr const char* kSnapshotTopic = "impetus_view_snapshot";

impetus_dds_Vec3 to_dds(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 from_dds(const impetus_dds_Vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

struct DdsWorldViewPublisher::State {
  explicit State(const DdsLinkOptions& options) : participant(options), world_id(new_session_id()) {
    const dds_entity_t publisher = make_publisher(participant.handle(), options.partition);
    scene_writer = make_writer(publisher, make_topic(participant.handle(), &impetus_dds_ViewScene_desc, kSceneTopic),
                               Delivery::reliable_durable);
    snapshot_writer = make_writer(
        publisher, make_topic(participant.handle(), &impetus_dds_WorldSnapshot_desc, kSnapshotTopic),
        Delivery::best_effort);
    allocate_sequence(scene.bodies, kMaxViewBodies);
    allocate_sequence(snapshot.endpoints, kMaxViewEndpoints);
    allocate_sequence(snapshot.bodies, kMaxViewBodies);
    allocate_sequence(snapshot.dent_depth_m, kMaxViewDentSide * kMaxViewDentSide);
  }
  ~State() {
    dds_sample_free(&scene, &impetus_dds_ViewScene_desc, DDS_FREE_CONTENTS);
    dds_sample_free(&snapshot, &impetus_dds_WorldSnapshot_desc, DDS_FREE_CONTENTS);
  }

  DdsParticipant participant;
  std::uint64_t world_id;
  dds_entity_t scene_writer = 0;
  dds_entity_t snapshot_writer = 0;
  impetus_dds_ViewScene scene{};
  impetus_dds_WorldSnapshot snapshot{};
};

DdsWorldViewPublisher::DdsWorldViewPublisher(const DdsLinkOptions& options)
    : state_(std::make_unique<State>(options)) {}
DdsWorldViewPublisher::~DdsWorldViewPublisher() = default;

void DdsWorldViewPublisher::publish_scene(const ViewScene& scene) {
  impetus_dds_ViewScene& out = state_->scene;
  out.world_id = state_->world_id;
  out.world_session = scene.world_session;
  out.coupling = static_cast<std::uint32_t>(scene.coupling);
  out.floor_present = scene.floor_present;
  out.floor_height_m = scene.floor_height_m;
  out.world_rate_hz = scene.world_rate_hz;
  const std::uint32_t count = std::min(scene.body_count, kMaxViewBodies);
  for (std::uint32_t k = 0; k < count; ++k) {
    const ViewBodyInfo& body = scene.bodies[k];
    impetus_dds_ViewBodyInfo& to = out.bodies._buffer[k];
    to.shape = static_cast<std::uint32_t>(body.shape.kind);
    to.dynamic = body.dynamic;
    to.box_size_m = to_dds(body.shape.box_size_m);
    to.radius_m = body.shape.radius_m;
    to.length_m = body.shape.length_m;
    to.mesh_hash = body.shape.mesh_hash;
    std::memcpy(to.name, body.name.data(), kMaxViewNameBytes);
  }
  out.bodies._length = count;
  dds_write(state_->scene_writer, &out);  // a viewer is a bystander: what cannot be sent is not the world's problem
}

void DdsWorldViewPublisher::publish_snapshot(const WorldSnapshot& snapshot) {
  impetus_dds_WorldSnapshot& out = state_->snapshot;
  out.world_id = state_->world_id;
  out.world_session = snapshot.world_session;
  out.frame_index = snapshot.frame_index;
  out.world_time_s = snapshot.world_time_s;
  out.world_period_s = snapshot.world_period_s;
  to_dds(snapshot.world_stats, out.world_stats);
  to_dds(snapshot.haptic_stats, out.haptic_stats);
  const std::uint32_t endpoints = std::min(snapshot.endpoint_count, kMaxViewEndpoints);
  for (std::uint32_t k = 0; k < endpoints; ++k) {
    const ViewEndpoint& from = snapshot.endpoints[k];
    impetus_dds_ViewEndpoint& to = out.endpoints._buffer[k];
    to.endpoint = from.endpoint;
    to.finger_valid = from.finger_valid;
    to.finger_m = to_dds(from.finger_m);
    to.proxy_m = to_dds(from.proxy_m);
    to.force_N = to_dds(from.force_N);
    to.oriented = from.oriented;
    to.torque_Nm = to_dds(from.torque_Nm);
    std::copy(from.finger_wxyz.begin(), from.finger_wxyz.end(), to.finger_wxyz);
    std::copy(from.proxy_wxyz.begin(), from.proxy_wxyz.end(), to.proxy_wxyz);
    to.plane_count = std::min(from.plane_count, kMaxViewPlanes);
    for (std::uint32_t p = 0; p < to.plane_count; ++p) {
      to.planes[p].point_m = to_dds(from.planes[p].point_m);
      to.planes[p].normal = to_dds(from.planes[p].normal);
    }
  }
  out.endpoints._length = endpoints;
  const std::uint32_t bodies = std::min(snapshot.body_count, kMaxViewBodies);
  for (std::uint32_t k = 0; k < bodies; ++k) {
    out.bodies._buffer[k].position_m = to_dds(snapshot.bodies[k].position_m);
    std::copy(snapshot.bodies[k].orientation_wxyz.begin(), snapshot.bodies[k].orientation_wxyz.end(),
              out.bodies._buffer[k].orientation_wxyz);
  }
  out.bodies._length = bodies;
  const ViewDent& dent = snapshot.dent;
  out.dent_object = dent.object_id;
  out.dent_columns = dent.columns;
  out.dent_rows = dent.rows;
  out.dent_version = dent.version;
  out.dent_x0_m = dent.x0_m;
  out.dent_y0_m = dent.y0_m;
  out.dent_dx_m = dent.dx_m;
  out.dent_dy_m = dent.dy_m;
  const std::uint32_t samples =
      dent.object_id >= 0 ? std::min(dent.columns * dent.rows, kMaxViewDentSide * kMaxViewDentSide) : 0;
  std::copy(dent.depth_m.begin(), dent.depth_m.begin() + samples, out.dent_depth_m._buffer);
  out.dent_depth_m._length = samples;
  dds_write(state_->snapshot_writer, &out);
}

struct DdsWorldViewReader::State {
  explicit State(const DdsLinkOptions& options) : participant(options), name(describe(options)) {
    const dds_entity_t subscriber = make_subscriber(participant.handle(), options.partition);
    scene_reader = make_reader(subscriber, make_topic(participant.handle(), &impetus_dds_ViewScene_desc, kSceneTopic),
                               Delivery::reliable_durable);
    snapshot_reader = make_reader(
        subscriber, make_topic(participant.handle(), &impetus_dds_WorldSnapshot_desc, kSnapshotTopic),
        Delivery::best_effort);
  }
  ~State() {
    if (have_scene_sample) dds_sample_free(&scene, &impetus_dds_ViewScene_desc, DDS_FREE_CONTENTS);
    if (have_snapshot_sample) dds_sample_free(&snapshot, &impetus_dds_WorldSnapshot_desc, DDS_FREE_CONTENTS);
  }

  DdsParticipant participant;
  std::string name;
  dds_entity_t scene_reader = 0;
  dds_entity_t snapshot_reader = 0;
  // Samples DDS fills (their sequences are allocated by DDS on the first take and reused after).
  impetus_dds_ViewScene scene{};
  impetus_dds_WorldSnapshot snapshot{};
  bool have_scene_sample = false;
  bool have_snapshot_sample = false;
  std::uint64_t rejected = 0;
};

DdsWorldViewReader::DdsWorldViewReader(const DdsLinkOptions& options) : state_(std::make_unique<State>(options)) {}
DdsWorldViewReader::~DdsWorldViewReader() = default;
std::uint64_t DdsWorldViewReader::rejected() const { return state_->rejected; }
const std::string& DdsWorldViewReader::name() const { return state_->name; }

namespace {

// Takes the newest valid sample of `reader` into `sample` (user-provided memory: DDS reuses its sequences); false if
// none came since the last call.
template <class Sample>
bool take_newest(dds_entity_t reader, Sample& sample, bool& have_sample) {
  bool got = false;
  void* buffer = &sample;
  dds_sample_info_t info{};
  while (dds_take(reader, &buffer, &info, 1, 1) > 0) {
    have_sample = true;
    if (info.valid_data) got = true;
  }
  return got;
}

}  // namespace

bool DdsWorldViewReader::read_scene(ViewScene& out) {
  State& state = *state_;
  if (!take_newest(state.scene_reader, state.scene, state.have_scene_sample)) return false;
  const impetus_dds_ViewScene& in = state.scene;
  if (in.bodies._length > kMaxViewBodies) {
    ++state.rejected;
    return false;
  }
  ViewScene scene{};
  scene.world_session = in.world_session;
  scene.coupling = static_cast<Coupling>(in.coupling);
  scene.floor_present = in.floor_present;
  scene.floor_height_m = in.floor_height_m;
  scene.world_rate_hz = in.world_rate_hz;
  scene.body_count = in.bodies._length;
  for (std::uint32_t k = 0; k < scene.body_count; ++k) {
    const impetus_dds_ViewBodyInfo& from = in.bodies._buffer[k];
    ViewBodyInfo& to = scene.bodies[k];
    to.shape.kind = static_cast<ShapeKind>(from.shape);
    to.dynamic = from.dynamic;
    to.shape.box_size_m = from_dds(from.box_size_m);
    to.shape.radius_m = from.radius_m;
    to.shape.length_m = from.length_m;
    to.shape.mesh_hash = from.mesh_hash;
    std::memcpy(to.name.data(), from.name, kMaxViewNameBytes);
    to.name.back() = '\0';
  }
  if (*scene_problem(scene) != '\0') {
    ++state.rejected;
    return false;
  }
  out = scene;
  return true;
}

bool DdsWorldViewReader::read_snapshot(WorldSnapshot& out) {
  State& state = *state_;
  if (!take_newest(state.snapshot_reader, state.snapshot, state.have_snapshot_sample)) return false;
  const impetus_dds_WorldSnapshot& in = state.snapshot;
  if (in.bodies._length > kMaxViewBodies || in.endpoints._length > kMaxViewEndpoints ||
      in.dent_depth_m._length > kMaxViewDentSide * kMaxViewDentSide) {
    ++state.rejected;
    return false;
  }
  out.world_session = in.world_session;
  out.frame_index = in.frame_index;
  out.world_time_s = in.world_time_s;
  out.world_period_s = in.world_period_s;
  from_dds(in.world_stats, out.world_stats);
  from_dds(in.haptic_stats, out.haptic_stats);
  out.endpoint_count = in.endpoints._length;
  for (std::uint32_t k = 0; k < out.endpoint_count; ++k) {
    const impetus_dds_ViewEndpoint& from = in.endpoints._buffer[k];
    ViewEndpoint& to = out.endpoints[k];
    to = ViewEndpoint{};
    to.endpoint = from.endpoint;
    to.finger_valid = from.finger_valid;
    to.finger_m = from_dds(from.finger_m);
    to.proxy_m = from_dds(from.proxy_m);
    to.force_N = from_dds(from.force_N);
    to.oriented = from.oriented;
    to.torque_Nm = from_dds(from.torque_Nm);
    std::copy(std::begin(from.finger_wxyz), std::end(from.finger_wxyz), to.finger_wxyz.begin());
    std::copy(std::begin(from.proxy_wxyz), std::end(from.proxy_wxyz), to.proxy_wxyz.begin());
    to.plane_count = std::min(from.plane_count, kMaxViewPlanes);
    for (std::uint32_t p = 0; p < to.plane_count; ++p) {
      to.planes[p].point_m = from_dds(from.planes[p].point_m);
      to.planes[p].normal = from_dds(from.planes[p].normal);
    }
  }
  out.body_count = in.bodies._length;
  for (std::uint32_t k = 0; k < out.body_count; ++k) {
    out.bodies[k].position_m = from_dds(in.bodies._buffer[k].position_m);
    std::copy(in.bodies._buffer[k].orientation_wxyz, in.bodies._buffer[k].orientation_wxyz + 4,
              out.bodies[k].orientation_wxyz.begin());
  }
  out.dent = ViewDent{};
  out.dent.object_id = in.dent_object;  // snapshot_problem refuses a bad one
  if (in.dent_object >= 0) {
    // The depths must fill the grid the header names (snapshot_problem checks the rest).
    if (static_cast<std::uint64_t>(in.dent_columns) * in.dent_rows != in.dent_depth_m._length) {
      ++state.rejected;
      return false;
    }
    out.dent.columns = in.dent_columns;
    out.dent.rows = in.dent_rows;
    out.dent.version = in.dent_version;
    out.dent.x0_m = in.dent_x0_m;
    out.dent.y0_m = in.dent_y0_m;
    out.dent.dx_m = in.dent_dx_m;
    out.dent.dy_m = in.dent_dy_m;
    std::copy(in.dent_depth_m._buffer, in.dent_depth_m._buffer + in.dent_depth_m._length, out.dent.depth_m.begin());
  }
  if (*snapshot_problem(out) != '\0') {
    ++state.rejected;
    return false;
  }
  return true;
}

}  // namespace impetus
