// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/shape_planes.h"


#include <array>

namespace impetus {
namespace {

bool in_front(const ContactPlane& plane, const Eigen::Vector3d& x_m) {
  return plane.normal.dot(x_m - plane.point_m) >= -kOnSurface_m;
}

// The body's plane at its point nearest the way from `from_m` to `to_m`, which passes the body: the supporting plane
// there separates the two (they are convex), so both ends are in front of it. The body's distance is convex along the
// way; a golden-section search finds its least to 1e-10 of the way (48 steps), each a retake about a point of the way.
ContactPlane nearest_to_way(const ContactPlane& as_sent, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m) {
  auto at = [&](double t, ContactPlane& plane) {
    plane = as_sent;
    const Eigen::Vector3d x_m = from_m + t * (to_m - from_m);
    retake_plane(plane, x_m);
    return plane.normal.dot(x_m - plane.point_m);
  };
  constexpr double kGolden = 0.6180339887498949;  // (√5 − 1)/2
  ContactPlane plane1, plane2;
  double lo = 0.0, hi = 1.0;
  double t1 = hi - kGolden * (hi - lo), t2 = lo + kGolden * (hi - lo);
  double d1 = at(t1, plane1), d2 = at(t2, plane2);
  for (int step = 0; step < 48; ++step) {
    if (d1 < d2) {
      hi = t2, t2 = t1, d2 = d1, plane2 = plane1;
      t1 = hi - kGolden * (hi - lo);
      d1 = at(t1, plane1);
    } else {
      lo = t1, t1 = t2, d1 = d2, plane1 = plane2;
      t2 = lo + kGolden * (hi - lo);
      d2 = at(t2, plane2);
    }
  }
  return d1 < d2 ? plane1 : plane2;
}

}  // namespace

void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& around_m) {
  for (std::uint32_t k = 0; k < planes.count; ++k) retake_plane(planes.planes[k], around_m);
}

void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m,
                         MeshHold* mesh_hold) {
  // About the proxy, as always. A retake moves only the plane, not the body, so the plane as it came is its point and
  // normal, kept here (uninitialised storage: nothing is built per tick).
  std::array<Eigen::Vector3d, kMaxServoPlanes> sent_point_m, sent_normal;
  auto as_sent = [&](std::uint32_t k) {
    ContactPlane plane = planes.planes[k];
    plane.point_m = sent_point_m[k];
    plane.normal = sent_normal[k];
    return plane;
  };
  // Meshes whose triangles are here are walked together (mesh_walk.h): the triangles the proxy's way meets become
  // their planes and hold it, and the rest of this function leaves them alone. A mesh the walk holds nothing of gets
  // its plane about where the walk ended; if the walk met nothing, the straight way to the finger goes into no mesh.
  const std::uint32_t sent_count = planes.count;
  std::array<bool, kMaxServoPlanes> walked{};
  const bool held_by_mesh = walk_mesh_planes(planes, proxy_m, finger_m, walked, mesh_hold) > 0;
  bool finger_held = false;
  for (std::uint32_t k = 0; k < sent_count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (walked[k] || !plane.shaped()) continue;
    sent_point_m[k] = plane.point_m;
    sent_normal[k] = plane.normal;
    retake_plane(plane, proxy_m);
    finger_held = finger_held || !in_front(plane, finger_m);
  }
  if (!finger_held || held_by_mesh) return;
  // Is the straight way from the proxy to the finger clear of every body? Any one it enters holds the proxy back,
  // and the proxy then slides along that body, where the others may meet it: only a way clear of all lets it go.
  for (std::uint32_t k = 0; k < sent_count; ++k) {
    if (walked[k]) continue;  // the walk went to the finger: the way goes into no mesh
    const ContactPlane& plane = planes.planes[k];
    const bool enters = plane.shaped() ? segment_enters(plane, proxy_m, finger_m, kOnSurface_m)
                                             : !in_front(plane, proxy_m) || !in_front(plane, finger_m);
    if (enters) return;
  }
  // Clear: every body behind a plane with both ends of the way in front. The one about the proxy if the finger is in
  // front of it; else the finger's supporting plane, if the proxy is in front of that; else the plane at the body's
  // point nearest the way.
  for (std::uint32_t k = 0; k < sent_count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (walked[k] || !plane.shaped() || in_front(plane, finger_m)) continue;
    const ContactPlane sent = as_sent(k);
    ContactPlane at_finger = sent;
    retake_plane(at_finger, finger_m);
    plane = in_front(at_finger, proxy_m) ? at_finger : nearest_to_way(sent, proxy_m, finger_m);
  }
}

}  // namespace impetus
