// SPDX-License-Identifier: Apache-2.0
#pragma once
// Builders shared by the haptic_controller tests.

#include "common/contract/frames.h"
#include "common/shape/shape.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/device/haptic_device.h"
#include "haptic_controller/device/spidar_kinematics.h"

#include <Eigen/Core>

#include <initializer_list>

namespace impetus::test {

// The finger sample a SPIDAR driver reads for a finger at `finger_m`: through the encoders (rounded to whole counts)
// and back, as on the device.
inline FingerSample finger_at(const SpidarKinematics& kinematics, const Eigen::Vector3d& finger_m) {
  FingerSample sample;
  sample.valid = kinematics.finger_position(kinematics.encoder_counts(finger_m), sample.position_m);
  return sample;
}

inline ContactPlane make_plane(const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal, int object_id = 0,
                               bool dynamic = false, double static_friction = 0.0, double dynamic_friction = 0.0) {
  ContactPlane plane;
  plane.object_id = object_id;
  plane.flags = dynamic ? kPlaneDynamic : 0u;
  plane.point_m = point_m;
  plane.normal = normal.normalized();
  plane.com_m = point_m - 0.025 * plane.normal;  // a 5 cm object behind its surface
  plane.static_friction = static_friction;
  plane.dynamic_friction = dynamic_friction;
  return plane;
}

inline PlaneSet make_set(std::initializer_list<ContactPlane> planes) {
  PlaneSet set;
  for (const ContactPlane& plane : planes) set.planes[set.count++] = plane;
  return set;
}

inline Plane wire_plane(int object_id, const Eigen::Vector3d& point_m, const Eigen::Vector3d& normal,
                        bool dynamic = true) {
  Plane plane;
  plane.object_id = object_id;
  plane.flags = dynamic ? kPlaneDynamic : 0u;
  plane.point_m = to_vec3(point_m);
  plane.normal = to_vec3(normal.normalized());
  plane.com_m = to_vec3(point_m - 0.025 * normal.normalized());
  return plane;
}

// A box of half sizes `half_m`, and round shapes (`length_m` along body z: a capsule's between its cap centres, a
// cylinder's end to end).
inline Shape box_shape(const Eigen::Vector3d& half_m) {
  Shape shape;
  shape.kind = ShapeKind::box;
  shape.box_size_m = to_vec3(2.0 * half_m);
  return shape;
}
inline Shape round_shape(ShapeKind kind, double radius_m, double length_m = 0.0) {
  Shape shape;
  shape.kind = kind;
  shape.radius_m = radius_m;
  shape.length_m = length_m;
  return shape;
}
// Gives a world plane its body's shape, and for a shape that carries them its axes (the columns of `axes`); the
// extent the world would send with it.
inline void set_shape(Plane& plane, const Shape& shape, const Eigen::Matrix3d& axes = Eigen::Matrix3d::Identity()) {
  plane.shape = shape;
  plane.extent_m = plane_extent_m(shape);
  if (traits(shape.kind).carries_axes) {
    plane.body_axis_x = to_vec3(axes.col(0));
    plane.body_axis_y = to_vec3(axes.col(1));
  }
}

inline PlaneFrame make_frame(std::initializer_list<Plane> planes, std::uint64_t index = 0, double period_s = 0.05) {
  PlaneFrame frame;
  frame.frame_index = index;
  frame.world_session = 1;
  frame.world_period_s = period_s;
  for (const Plane& plane : planes) frame.planes[frame.plane_count++] = plane;
  return frame;
}

}  // namespace impetus::test
