// SPDX-License-Identifier: Apache-2.0
#include "common/contract/world_view.h"

#include "common/shape/shape.h"

#include <cmath>

namespace impetus {
namespace {

// Unit within 1e-6: what a renormalised double quaternion or normal always meets, and a scribbled one almost never.
constexpr double kUnitTolerance = 1e-6;

bool unit(double squared_norm) { return std::abs(squared_norm - 1.0) <= 2.0 * kUnitTolerance; }

bool unit(const Vec3& v) { return all_finite(v) && unit(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

bool unit(const std::array<double, 4>& q) {
  return std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && std::isfinite(q[3]) &&
         unit(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
}

}  // namespace

const char* snapshot_problem(const WorldSnapshot& snapshot) {
  if (snapshot.body_count > kMaxViewBodies) return "body count over capacity";
  if (snapshot.endpoint_count > kMaxViewEndpoints) return "endpoint count over capacity";
  if (!std::isfinite(snapshot.world_time_s) || !(snapshot.world_period_s > 0.0) ||
      !std::isfinite(snapshot.world_period_s)) {
    return "world time or period not finite and positive";
  }
  for (std::uint32_t k = 0; k < snapshot.body_count; ++k) {
    const ViewBodyPose& body = snapshot.bodies[k];
    if (!all_finite(body.position_m)) return "body position not finite";
    if (!unit(body.orientation_wxyz)) return "body orientation not a unit quaternion";
  }
  for (std::uint32_t e = 0; e < snapshot.endpoint_count; ++e) {
    const ViewEndpoint& endpoint = snapshot.endpoints[e];
    if (endpoint.plane_count > kMaxViewPlanes) return "plane count over capacity";
    if (!all_finite(endpoint.finger_m) || !all_finite(endpoint.proxy_m) || !all_finite(endpoint.force_N) ||
        !all_finite(endpoint.torque_Nm)) {
      return "finger, proxy, force or torque not finite";
    }
    if (!unit(endpoint.finger_wxyz) || !unit(endpoint.proxy_wxyz)) return "finger or proxy orientation not unit";
    for (std::uint32_t p = 0; p < endpoint.plane_count; ++p) {
      if (!all_finite(endpoint.planes[p].point_m)) return "plane point not finite";
      if (!unit(endpoint.planes[p].normal)) return "plane normal not unit";
    }
  }
  const ViewDent& dent = snapshot.dent;
  if (dent.object_id >= 0) {
    if (static_cast<std::uint32_t>(dent.object_id) >= snapshot.body_count) return "dent of a body not in the snapshot";
    if (dent.columns < 2 || dent.columns > kMaxViewDentSide || dent.rows < 2 || dent.rows > kMaxViewDentSide) {
      return "dent grid size out of range";
    }
    if (!std::isfinite(dent.x0_m) || !std::isfinite(dent.y0_m) || !(dent.dx_m > 0.0) || !(dent.dy_m > 0.0) ||
        !std::isfinite(dent.dx_m) || !std::isfinite(dent.dy_m)) {
      return "dent grid not finite and positive";
    }
    for (std::uint32_t k = 0; k < dent.columns * dent.rows; ++k) {
      if (!(dent.depth_m[k] >= 0.0f) || !std::isfinite(dent.depth_m[k])) return "dent depth not finite and >= 0";
    }
  } else if (dent.object_id != -1) {
    return "dent object id negative";
  }
  return "";
}

const char* scene_problem(const ViewScene& scene) {
  if (scene.body_count > kMaxViewBodies) return "body count over capacity";
  if (scene.coupling != Coupling::impulse && scene.coupling != Coupling::position && scene.coupling != Coupling::local) {
    return "unknown coupling";
  }
  if (!std::isfinite(scene.floor_height_m) || !(scene.world_rate_hz > 0.0) || !std::isfinite(scene.world_rate_hz)) {
    return "floor height or world rate not finite";
  }
  for (std::uint32_t k = 0; k < scene.body_count; ++k) {
    const ViewBodyInfo& body = scene.bodies[k];
    if (body.shape.kind == ShapeKind::none) return "a body without a shape";
    if (const char* problem = shape_problem(body.shape); problem != nullptr) return problem;
    if (body.name.back() != '\0') return "body name not terminated";
  }
  return "";
}

}  // namespace impetus
