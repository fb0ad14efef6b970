// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/plane_interpolator.h"

#include "haptic_controller/plane_matching.h"
#include "haptic_controller/plane_motion.h"

#include <algorithm>
#include <cmath>

namespace impetus {
namespace {

Eigen::Vector3d lerp(const Vec3& from, const Vec3& to, double w) {
  return (1.0 - w) * to_eigen(from) + w * to_eigen(to);
}

// A body's axes between frames i−1 and i: turned part of the way (the same body's in both frames, so they correspond
// one to one). A turn too large to interpolate (half a revolution in a period) takes frame i's.
void interpolate_axes(const Plane& before, const Plane& now, double w, ContactPlane& plane) {
  const Eigen::Vector3d x = lerp(before.body_axis_x, now.body_axis_x, w);
  const Eigen::Vector3d y = lerp(before.body_axis_y, now.body_axis_y, w);
  const Eigen::Vector3d y_across = y - y.dot(x) / x.squaredNorm() * x;
  if (!(x.norm() > 0.5) || !(y_across.norm() > 0.5)) return;
  const Eigen::Vector3d x_unit = x.normalized();
  const Eigen::Vector3d y_unit = y_across.normalized();
  plane.axes << x_unit, y_unit, x_unit.cross(y_unit);
}

}  // namespace

ContactPlane to_contact_plane(const Plane& plane) {
  ContactPlane out;
  out.object_id = plane.object_id;
  out.flags = plane.flags;
  out.point_m = to_eigen(plane.point_m);
  out.normal = to_eigen(plane.normal);
  out.com_m = to_eigen(plane.com_m);
  out.velocity_mps = to_eigen(plane.velocity_mps);
  out.angular_velocity_radps = to_eigen(plane.angular_velocity_radps);
  out.static_friction = plane.static_friction;
  out.dynamic_friction = plane.dynamic_friction;
  out.extent_m = plane.extent_m;
  out.yield_force_N = plane.yield_force_N;
  out.yield_depth_mpNs = plane.yield_depth_mpNs;
  out.yield_radius_m = plane.yield_radius_m;
  out.yield_room_m = plane.yield_room_m;
  out.yield_compliance_mpN = plane.yield_compliance_mpN;
  out.shape = plane.shape;
  if (traits(plane.shape.kind).carries_axes) {
    const Eigen::Vector3d x = to_eigen(plane.body_axis_x);
    const Eigen::Vector3d y = to_eigen(plane.body_axis_y);
    out.axes << x, y, x.cross(y);
  }
  return out;
}

double interpolation_weight(double now_s, double frame_arrival_s, double world_period_s) {
  const double w = (now_s - frame_arrival_s) / world_period_s;
  if (!(world_period_s > 0.0) || !std::isfinite(w)) return 1.0;
  return std::clamp(w, 0.0, 1.0);
}

void interpolate_planes(const PlaneFrame& previous, const PlaneFrame& current, double w,
                        const Eigen::Vector3d& pivot_m, PlaneSet& out) {
  PlaneMatches matches;
  match_planes(previous, current, matches);
  interpolate_planes(previous, current, matches, w, pivot_m, out);
}

void interpolate_planes(const PlaneFrame& previous, const PlaneFrame& current, const PlaneMatches& matches, double w,
                        const Eigen::Vector3d& pivot_m, PlaneSet& out) {
  w = std::isfinite(w) ? std::clamp(w, 0.0, 1.0) : 1.0;
  const std::uint32_t count = std::min(current.plane_count, kMaxPlanes);
  out.count = count;
  for (std::uint32_t k = 0; k < count; ++k) {
    const Plane& now = current.planes[k];
    ContactPlane& plane = out.planes[k];
    plane = to_contact_plane(now);  // velocities, friction, flags: frame i's

    const int match = matches.previous_index[k];
    if (match < 0) continue;  // new object: starts at frame i's value
    const Plane& before = previous.planes[match];
    // A body that carries its axes in both frames: they turn between them (the same body's: one to one).
    const bool axes_both = plane.shape_traits().carries_axes && traits(before.shape.kind).carries_axes;

    if (normals_flip(to_eigen(before.normal), to_eigen(now.normal))) {
      const Plane& face = flip_switched(w) ? now : before;
      if (axes_both) {
        // A body that carries its shape moves between the frames whichever face is shown: the face is carried
        // rigidly from its frame's pose to the interpolated one (a face held where frame i−1 left it would let a body
        // that comes at the finger close over the proxy for half a period).
        plane.com_m = lerp(before.com_m, now.com_m, w);
        interpolate_axes(before, now, w, plane);  // frame i's axes when the turn is too large to interpolate
        const Eigen::Vector3d face_x = to_eigen(face.body_axis_x), face_y = to_eigen(face.body_axis_y);
        Eigen::Matrix3d face_axes;
        face_axes << face_x, face_y, face_x.cross(face_y);
        const Eigen::Matrix3d turn = plane.axes * face_axes.transpose();
        plane.point_m = plane.com_m + turn * (to_eigen(face.point_m) - to_eigen(face.com_m));
        plane.normal = (turn * to_eigen(face.normal)).normalized();
      } else if (&face == &before) {
        plane.point_m = to_eigen(before.point_m);
        plane.normal = to_eigen(before.normal);
        plane.com_m = to_eigen(before.com_m);
      }
      continue;
    }
    plane.com_m = lerp(before.com_m, now.com_m, w);
    if (axes_both) interpolate_axes(before, now, w, plane);
    const Eigen::Vector3d normal = lerp(before.normal, now.normal, w);
    plane.normal = normal / normal.norm();  // |normal| ≥ 1/√2 for unit inputs with dot ≥ 0
    if (plane.shape_traits().round) {
      // A ball: its centre moves between the frames, its tangent plane is taken again at the proxy (shape_planes.h).
      const double radius_m = plane.shape.radius_m;
      const Eigen::Vector3d centre_before = to_eigen(before.point_m) - radius_m * to_eigen(before.normal);
      const Eigen::Vector3d centre_now = to_eigen(now.point_m) - radius_m * to_eigen(now.normal);
      plane.point_m = (1.0 - w) * centre_before + w * centre_now + radius_m * plane.normal;
      continue;
    }
    // The plane's offset at the pivot moves linearly from frame i−1's to frame i's (header).
    const Eigen::Vector3d point = lerp(before.point_m, now.point_m, w);
    const double offset_before = to_eigen(before.normal).dot(pivot_m - to_eigen(before.point_m));
    const double offset_now = to_eigen(now.normal).dot(pivot_m - to_eigen(now.point_m));
    const double offset = (1.0 - w) * offset_before + w * offset_now;
    plane.point_m = point + (plane.normal.dot(pivot_m - point) - offset) * plane.normal;
  }
}

}  // namespace impetus

namespace impetus {

void InterpolatedPlanes::on_frame(const PlaneFrame& previous, const PlaneFrame& frame, const PlaneSet*,
                                  const Eigen::Vector3d&) {
  copy_used(previous, previous_);
  copy_used(frame, current_);
  match_planes(previous_, current_, matches_);
}

void InterpolatedPlanes::planes_for_tick(double w, double, bool, const Eigen::Vector3d& pivot_m, PlaneSet& out) {
  interpolate_planes(previous_, current_, matches_, w, pivot_m, out);
}

}  // namespace impetus
