// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world_view.h"

#include <algorithm>
#include <cstring>

namespace impetus {
namespace {

double squared_distance(const Vec3& a, const Vec3& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

void describe_scene(const Scene& scene, Coupling coupling, double world_rate_hz, std::uint64_t world_session,
                    ViewScene& out) {
  out.world_session = world_session;
  out.coupling = coupling;
  out.floor_present = scene.floor.present ? 1 : 0;
  out.floor_height_m = scene.floor.height_m;
  out.world_rate_hz = world_rate_hz;
  out.body_count = static_cast<std::uint32_t>(std::min<std::size_t>(scene.objects.size(), kMaxViewBodies));
  for (std::uint32_t k = 0; k < out.body_count; ++k) {
    const SceneObject& object = scene.objects[k];
    ViewBodyInfo& body = out.bodies[k];
    body.shape = object.shape;
    body.dynamic = object.dynamic ? 1 : 0;
    body.name.fill('\0');
    std::memcpy(body.name.data(), object.name.data(), std::min(object.name.size(), body.name.size() - 1));
  }
}

ViewBodyPose scene_pose(const SceneObject& object) {
  return {object.position_m, object.orientation_wxyz};
}

void take_snapshot(const World& world, std::span<const HapticReport* const> reports, const LoopStats& world_stats,
                   const LoopStats* haptic_stats, WorldSnapshot& out) {
  const PlaneFrame& header = world.frame();
  out.world_session = header.world_session;
  out.frame_index = header.frame_index;
  out.world_time_s = world.time_s();
  out.world_period_s = world.world_period_s();
  out.world_stats = world_stats;
  out.haptic_stats = haptic_stats != nullptr ? *haptic_stats : LoopStats{};

  const auto states = world.states();
  out.body_count = static_cast<std::uint32_t>(std::min<std::size_t>(states.size(), kMaxViewBodies));
  for (std::uint32_t k = 0; k < out.body_count; ++k) {
    const BodyPose& pose = states[k].pose;
    out.bodies[k].position_m = to_vec3(pose.position_m);
    out.bodies[k].orientation_wxyz = {pose.orientation.w(), pose.orientation.x(), pose.orientation.y(),
                                      pose.orientation.z()};
  }

  // The first deformable object with a dent.
  out.dent = ViewDent{};
  for (std::uint32_t k = 0; k < out.body_count && out.dent.object_id < 0; ++k) {
    if (const DeformableSurface* surface = world.deformable(k); surface != nullptr) {
      surface->view_dent(static_cast<std::int32_t>(k), out.dent);
    }
  }

  out.endpoint_count = 0;
  for (std::size_t slot = 0; slot < reports.size() && slot < world.endpoint_slots(); ++slot) {
    const HapticReport* report = reports[slot];
    if (report == nullptr || out.endpoint_count >= kMaxViewEndpoints) continue;
    const PlaneFrame& frame = world.frame(slot);
    ViewEndpoint& endpoint = out.endpoints[out.endpoint_count++];
    endpoint.endpoint = report->endpoint;
    endpoint.finger_valid = report->finger_valid;
    endpoint.finger_m = report->finger_m;
    endpoint.proxy_m = report->proxy_m;
    endpoint.force_N = report->force_N;
    endpoint.oriented = report->oriented;
    endpoint.torque_Nm = report->torque_Nm;
    endpoint.finger_wxyz = report->finger_wxyz;
    endpoint.proxy_wxyz = report->proxy_wxyz;
    // The planes nearest the proxy: those the finger can be touching. Selection on at most kMaxPlanes indices.
    std::array<std::uint32_t, kMaxPlanes> order{};
    const std::uint32_t count = std::min(frame.plane_count, kMaxPlanes);
    for (std::uint32_t p = 0; p < count; ++p) order[p] = p;
    const std::uint32_t shown = std::min(count, kMaxViewPlanes);
    std::partial_sort(order.begin(), order.begin() + shown, order.begin() + count,
                      [&](std::uint32_t a, std::uint32_t b) {
                        return squared_distance(frame.planes[a].point_m, report->proxy_m) <
                               squared_distance(frame.planes[b].point_m, report->proxy_m);
                      });
    endpoint.plane_count = shown;
    for (std::uint32_t p = 0; p < shown; ++p) {
      endpoint.planes[p].point_m = frame.planes[order[p]].point_m;
      endpoint.planes[p].normal = frame.planes[order[p]].normal;
    }
  }
}

}  // namespace impetus
