// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/shape_planes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace impetus {
namespace {

// A proxy this close to a face's rim is still on the face: the god-object puts a proxy that slides up to an edge on
// it only to rounding (~1e-17 m), and a point on the surface has no direction to take a normal from.
constexpr double kOnSurface_m = 1e-9;
// A plane within 1° of a face's normal is that face's, as the interpolation or the local model turned it (the local
// model's blend toward a new frame turns a face by a fraction of what the body turned in one period); an edge's or a
// corner's plane from the world is tilted by more unless the proxy was within 1/57 of its distance of the face plane.
constexpr double kSameFaceCosine = 0.99984769515;  // cos 1°

void retake_sphere(ContactPlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d centre_m = plane.point_m - plane.extent_m * plane.normal;
  const Eigen::Vector3d offset_m = around_m - centre_m;
  const double distance_m = offset_m.norm();
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) return;
  plane.normal = offset_m / distance_m;
  plane.point_m = centre_m + plane.extent_m * plane.normal;
}

// A capsule: the sphere of its radius about the axis point nearest `around_m` (the axis is the body's z through com_m,
// between the cap centres at ±box_half_m[2]).
void retake_capsule(ContactPlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d axis = plane.box_axes.col(2);
  const double half_length_m = plane.box_half_m.z();
  const double along_m = std::clamp(axis.dot(around_m - plane.com_m), -half_length_m, half_length_m);
  const Eigen::Vector3d centre_m = plane.com_m + along_m * axis;
  const Eigen::Vector3d offset_m = around_m - centre_m;
  const double distance_m = offset_m.norm();
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) return;  // on the axis: no direction, the plane stays
  plane.normal = offset_m / distance_m;
  plane.point_m = centre_m + plane.extent_m * plane.normal;
}

// A cylinder: its side is curved, its caps flat. The plane is the side's (normal square to the axis) or a cap's (the
// normal nearer the axis). Beside the side a side plane is the tangent plane under the proxy; over its cap a cap plane
// stays as the interpolation or the local model made it, as a box face's does; past the plane's own part (round a
// rim, or onto the other part) the cylinder's nearest point, its normal from there to the proxy. A proxy on the
// surface gets the plane of the part it is on: its own cap's plane as it came, the side's tangent plane there, a cap's
// plane on a cap. Inside it gets the part the world chose (the one the plane faces), on the true surface.
//
// On the surface the plane must be the part's own even when it came tilted: a plane blended between a rim's and the
// side's (the proxy went round the rim between two frames) kept under a proxy on the side would carry the proxy off
// the surface onto the tilt, the next tick would bring it back to the side's tangent plane, and so on, a tick-by-tick
// hop of millimetres.
void retake_cylinder(ContactPlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d local_m = plane.box_axes.transpose() * (around_m - plane.com_m);  // body frame, axis z
  const double radius_m = plane.extent_m;
  const double half_length_m = plane.box_half_m.z();
  const Eigen::Vector3d normal_local = plane.box_axes.transpose() * plane.normal;
  const bool cap_plane = std::abs(normal_local.z()) > std::hypot(normal_local.x(), normal_local.y());
  const double radial_m = std::hypot(local_m.x(), local_m.y());
  const bool beside = radial_m > radius_m + kOnSurface_m;
  const bool beyond_cap = std::abs(local_m.z()) > half_length_m + kOnSurface_m;
  // Over its own cap a cap's plane stays; a rim's plane from the world (tilted off the axis) becomes the cap's there,
  // as a box edge's plane becomes its face's (retake_box).
  const bool cap_as_moved = cap_plane && std::abs(normal_local.z()) >= kSameFaceCosine;
  if (!beside && !beyond_cap) {
    const bool on_side = radial_m >= radius_m - kOnSurface_m && radial_m > 0.0;
    const bool on_cap = std::abs(local_m.z()) >= half_length_m - kOnSurface_m;
    if (!on_side && !on_cap) {
      // Inside (the body moved onto the proxy): the part the world chose, but its own plane there, not a blend that
      // cuts into the body (between a rim's plane and a part's it passes inside the rim).
      if (cap_plane) {
        if (cap_as_moved) return;
        const double side = normal_local.z() > 0.0 ? 1.0 : -1.0;
        plane.normal = side * plane.box_axes.col(2);
        plane.point_m = plane.com_m + plane.box_axes * Eigen::Vector3d(local_m.x(), local_m.y(), side * half_length_m);
        return;
      }
      // The side at the azimuth the plane faces: exact even for a plane blended between two frames' tangent planes,
      // which lies on their chord, inside the side (r·(1 − cos(Δθ/2)): 0.5 mm for 36° on a 1 cm radius).
      const double out_m = std::hypot(normal_local.x(), normal_local.y());
      if (!(out_m > 0.0)) return;
      const Eigen::Vector3d out_local(normal_local.x() / out_m, normal_local.y() / out_m, 0.0);
      plane.normal = plane.box_axes * out_local;
      plane.point_m = plane.com_m + plane.box_axes * Eigen::Vector3d(radius_m * out_local.x(),
                                                                     radius_m * out_local.y(), local_m.z());
      return;
    }
    const double cap_side = local_m.z() >= 0.0 ? 1.0 : -1.0;
    if (on_cap && (!on_side || cap_plane)) {
      if (cap_as_moved && cap_side * normal_local.z() > 0.0) return;
      plane.normal = cap_side * plane.box_axes.col(2);
      plane.point_m =
          plane.com_m + plane.box_axes * Eigen::Vector3d(local_m.x(), local_m.y(), cap_side * half_length_m);
      return;
    }
    const Eigen::Vector3d out_local(local_m.x() / radial_m, local_m.y() / radial_m, 0.0);
    plane.normal = plane.box_axes * out_local;
    plane.point_m = plane.com_m + plane.box_axes * Eigen::Vector3d(radius_m * out_local.x(), radius_m * out_local.y(),
                                                                   local_m.z());
    return;
  }
  if (cap_as_moved && !beside && local_m.z() * normal_local.z() > 0.0) return;
  Eigen::Vector3d nearest_local_m(local_m.x(), local_m.y(), std::clamp(local_m.z(), -half_length_m, half_length_m));
  if (beside) nearest_local_m.head<2>() *= radius_m / radial_m;
  const Eigen::Vector3d offset_local_m = local_m - nearest_local_m;
  const double distance_m = offset_local_m.norm();
  if (!(distance_m > 0.0) || !std::isfinite(distance_m)) return;
  plane.normal = plane.box_axes * (offset_local_m / distance_m);
  plane.point_m = plane.com_m + plane.box_axes * nearest_local_m;
}

void retake_box(ContactPlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d local_m = plane.box_axes.transpose() * (around_m - plane.com_m);  // box frame
  const Eigen::Vector3d& half_m = plane.box_half_m;
  // The plane's face: the one whose normal is nearest the plane's. The plane is that face's as the interpolation or
  // the local model moved it, which may turn it off the box's axis a little (the local model's blend toward a new
  // frame); an edge's plane counts as its nearer face's, as the world gave it while the proxy stays over that face.
  const Eigen::Vector3d normal_local = plane.box_axes.transpose() * plane.normal;
  int face_axis = 0;
  normal_local.cwiseAbs().maxCoeff(&face_axis);
  const double face_side = normal_local[face_axis] > 0.0 ? 1.0 : -1.0;

  const Eigen::Vector3d nearest_local_m = local_m.cwiseMax(-half_m).cwiseMin(half_m);
  Eigen::Vector3d offset_local_m = local_m - nearest_local_m;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(offset_local_m[axis]) <= kOnSurface_m) offset_local_m[axis] = 0.0;  // on the rim, to rounding
  }
  const double distance_m = offset_local_m.norm();
  if (distance_m > 0.0 && std::isfinite(distance_m)) {
    // Outside: over the plane's own face (the nearest point on it, the offset along its normal) the plane stays as
    // the interpolation or the local model made it; anywhere else the box's nearest edge, corner or face.
    const bool over_face = offset_local_m[face_axis] * face_side > 0.0 &&
                           offset_local_m.squaredNorm() == offset_local_m[face_axis] * offset_local_m[face_axis];
    // Over its face the face's plane stays. An edge's or a corner's plane (the world took it with its proxy past the
    // rim) tilts away from the face it is counted to: kept over the face it hangs above the face, millimetres off the
    // box a few millimetres in, and the proxy slides along it in free space. It becomes the face's plane there.
    if (over_face && std::abs(normal_local[face_axis]) >= kSameFaceCosine) return;
    plane.normal = plane.box_axes * (offset_local_m / distance_m);
    plane.point_m = plane.com_m + plane.box_axes * nearest_local_m;
    return;
  }
  // On the surface (where the god-object leaves a proxy) or inside (the box moved onto it). A proxy deep inside keeps
  // the plane (the world chose the face: feature_memory.h; a plane blending from a face's toward the edge's the finger
  // slid past sinks into the box, and lets the finger go, as it should). A proxy on the plane's own face keeps the
  // plane only within 1° of the face, and otherwise gets the face's own plane: a blend between an edge's plane and a
  // face's kept under a proxy on the face would carry the proxy off the face, the next tick would bring it back, and
  // so on, a hop every tick. A proxy on another face (it went round an edge) gets that face: of the faces it is on,
  // the one nearest the plane's normal.
  const bool as_moved = std::abs(normal_local[face_axis]) >= kSameFaceCosine;
  int best_axis = -1;
  double best_side = 0.0, best_alignment = -2.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(local_m[axis]) < half_m[axis] - kOnSurface_m) continue;
    const double side = local_m[axis] >= 0.0 ? 1.0 : -1.0;
    if (axis == face_axis && side == face_side) {
      if (as_moved) return;
      best_axis = axis;
      best_side = side;
      break;
    }
    const double alignment = side * normal_local[axis];
    if (alignment > best_alignment) {
      best_axis = axis;
      best_side = side;
      best_alignment = alignment;
    }
  }
  if (best_axis < 0) return;
  Eigen::Vector3d on_face_m = local_m;
  on_face_m[best_axis] = best_side * half_m[best_axis];
  plane.normal = best_side * plane.box_axes.col(best_axis);
  plane.point_m = plane.com_m + plane.box_axes * on_face_m;
}

// Segment tests against a body shrunk by kOnSurface_m, so that a segment that starts on the surface (the proxy) and
// leaves it does not count as entering. `from_m` + t·(to_m − from_m), t in [0, 1].

// The parameter interval [t0, t1] the segment spends within |coordinate| ≤ half along one body axis; false if none.
bool clip_slab(double from, double delta, double half, double& t0, double& t1) {
  if (std::abs(delta) < 1e-300) return std::abs(from) < half;
  double ta = (-half - from) / delta, tb = (half - from) / delta;
  if (ta > tb) std::swap(ta, tb);
  t0 = std::max(t0, ta);
  t1 = std::min(t1, tb);
  return t0 < t1;
}

// Squared distance from the origin to the segment a + t·d, t in [t0, t1] (2-D or 3-D).
template <typename Vector>
double min_squared_norm(const Vector& a, const Vector& d, double t0, double t1) {
  const double dd = d.squaredNorm();
  const double t = dd > 0.0 ? std::clamp(-a.dot(d) / dd, t0, t1) : t0;
  return (a + t * d).squaredNorm();
}

bool segment_enters(const ContactPlane& plane, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m) {
  if (plane.sphere()) {
    const Eigen::Vector3d centre_m = plane.point_m - plane.extent_m * plane.normal;
    const double inner_m = plane.extent_m - kOnSurface_m;
    return min_squared_norm(Eigen::Vector3d(from_m - centre_m), Eigen::Vector3d(to_m - from_m), 0.0, 1.0) <
           inner_m * inner_m;
  }
  const Eigen::Vector3d a = plane.box_axes.transpose() * (from_m - plane.com_m);  // body frame
  const Eigen::Vector3d d = plane.box_axes.transpose() * (to_m - from_m);
  double t0 = 0.0, t1 = 1.0;
  if (plane.box()) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!clip_slab(a[axis], d[axis], plane.box_half_m[axis] - kOnSurface_m, t0, t1)) return false;
    }
    return true;
  }
  const double inner_m = plane.extent_m - kOnSurface_m;
  if (plane.cylinder()) {
    if (!clip_slab(a.z(), d.z(), plane.box_half_m.z() - kOnSurface_m, t0, t1)) return false;
    return min_squared_norm(Eigen::Vector2d(a.head<2>()), Eigen::Vector2d(d.head<2>()), t0, t1) < inner_m * inner_m;
  }
  // A capsule: the segment comes within the radius of its axis segment, z in [−half, half]. Along the segment the
  // squared distance to it is a quadratic on each stretch where z is below, within or above that range: the least of
  // their minima.
  const double half_m = plane.box_half_m.z();
  std::array<double, 4> cuts{0.0, 1.0, 1.0, 1.0};  // 0, the crossings of z = ±half inside (0, 1) in order, 1
  std::size_t stretches = 1;
  if (std::abs(d.z()) > 1e-300) {
    double first = (-half_m - a.z()) / d.z(), second = (half_m - a.z()) / d.z();
    if (first > second) std::swap(first, second);
    for (const double t : {first, second}) {
      if (t > 0.0 && t < 1.0) cuts[stretches++] = t;
    }
  }
  cuts[stretches] = 1.0;
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < stretches; ++k) {
    const double u = cuts[k], v = cuts[k + 1];
    const double z_mid = a.z() + 0.5 * (u + v) * d.z();
    if (std::abs(z_mid) <= half_m) {
      least = std::min(least, min_squared_norm(Eigen::Vector2d(a.head<2>()), Eigen::Vector2d(d.head<2>()), u, v));
    } else {
      const Eigen::Vector3d end_m(0.0, 0.0, z_mid > 0.0 ? half_m : -half_m);
      least = std::min(least, min_squared_norm(Eigen::Vector3d(a - end_m), d, u, v));
    }
  }
  return least < inner_m * inner_m;
}

void retake(ContactPlane& plane, const Eigen::Vector3d& around_m) {
  if (plane.sphere()) {
    retake_sphere(plane, around_m);
  } else if (plane.box()) {
    retake_box(plane, around_m);
  } else if (plane.capsule()) {
    retake_capsule(plane, around_m);
  } else if (plane.cylinder()) {
    retake_cylinder(plane, around_m);
  }
}

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
    retake(plane, x_m);
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

bool carries_shape(const ContactPlane& plane) {
  return plane.sphere() || plane.box() || plane.capsule() || plane.cylinder();
}

}  // namespace

void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& around_m) {
  for (std::uint32_t k = 0; k < planes.count; ++k) retake(planes.planes[k], around_m);
}

void retake_shape_planes(PlaneSet& planes, const Eigen::Vector3d& proxy_m, const Eigen::Vector3d& finger_m) {
  // About the proxy, as always. A retake moves only the plane, not the body, so the plane as it came is its point and
  // normal, kept here (uninitialised storage: nothing is built per tick).
  std::array<Eigen::Vector3d, kMaxPlanes> sent_point_m, sent_normal;
  auto as_sent = [&](std::uint32_t k) {
    ContactPlane plane = planes.planes[k];
    plane.point_m = sent_point_m[k];
    plane.normal = sent_normal[k];
    return plane;
  };
  bool finger_held = false;
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (!carries_shape(plane)) continue;
    sent_point_m[k] = plane.point_m;
    sent_normal[k] = plane.normal;
    retake(plane, proxy_m);
    finger_held = finger_held || !in_front(plane, finger_m);
  }
  if (!finger_held) return;
  // Is the straight way from the proxy to the finger clear of every body? Any one it enters holds the proxy back,
  // and the proxy then slides along that body, where the others may meet it: only a way clear of all lets it go.
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    const ContactPlane& plane = planes.planes[k];
    const bool enters = carries_shape(plane) ? segment_enters(plane, proxy_m, finger_m)
                                             : !in_front(plane, proxy_m) || !in_front(plane, finger_m);
    if (enters) return;
  }
  // Clear: every body behind a plane with both ends of the way in front. The one about the proxy if the finger is in
  // front of it; else the finger's supporting plane, if the proxy is in front of that; else the plane at the body's
  // point nearest the way.
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (!carries_shape(plane) || in_front(plane, finger_m)) continue;
    const ContactPlane sent = as_sent(k);
    ContactPlane at_finger = sent;
    retake(at_finger, finger_m);
    plane = in_front(at_finger, proxy_m) ? at_finger : nearest_to_way(sent, proxy_m, finger_m);
  }
}

}  // namespace impetus
