// SPDX-License-Identifier: Apache-2.0
// A box: full extents `box_size_m` along body x, y, z, centred on the centre of mass.
#include "common/shape/shape_kind.h"

#include "common/runtime/json_node.h"

#include <algorithm>
#include <cmath>

namespace impetus::shape_detail {
namespace {

Eigen::Vector3d half_sizes(const Shape& shape) { return 0.5 * to_eigen(shape.box_size_m); }

void parse(const JsonNode& object, Shape& shape) {
  const JsonNode size = object.required("size_m");
  shape.box_size_m = size.numbers<3>();
  for (std::size_t i = 0; i < 3; ++i) parse_length(size.element(i));
}

const char* problem(const Shape& shape) {
  for (const double size_m : shape.box_size_m) {
    if (!length_ok(size_m)) return "a box's size is out of range";
  }
  return nullptr;
}

SurfacePoint nearest(const Shape& shape, const Eigen::Vector3d& q) {
  const Eigen::Vector3d half_m = half_sizes(shape);
  const bool outside = (q.cwiseAbs().array() > half_m.array()).any();
  if (outside) {
    // The clamped point is the nearest point of a convex box; the normal is along the offset (face, edge or corner).
    const Eigen::Vector3d clamped = q.cwiseMax(-half_m).cwiseMin(half_m);
    const Eigen::Vector3d offset_m = q - clamped;
    const double distance_m = offset_m.norm();
    return {clamped, offset_m / distance_m, distance_m};
  }
  // Inside or on the surface: the face with the smallest gap is the nearest; ties go to the lowest axis, +side at 0.
  const Eigen::Vector3d gap_m = half_m - q.cwiseAbs();
  int axis = 0;
  gap_m.minCoeff(&axis);
  const double side = q[axis] >= 0.0 ? 1.0 : -1.0;
  Eigen::Vector3d point_m = q;
  point_m[axis] = side * half_m[axis];
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[axis] = side;
  return {point_m, normal, -gap_m[axis]};
}

double support(const Shape& shape, const Eigen::Vector3d& n) {
  return 0.5 * (to_eigen(shape.box_size_m).array() * n.array().abs()).sum();
}

Eigen::Vector3d bounds_half(const Shape& shape, const Eigen::Matrix3d& rotation) {
  return rotation.cwiseAbs() * half_sizes(shape);
}

bool segment_enters(const Shape& shape, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double margin_m) {
  const Eigen::Vector3d half_m = half_sizes(shape);
  double t0 = 0.0, t1 = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (!clip_slab(a[axis], d[axis], half_m[axis] - margin_m, t0, t1)) return false;
  }
  return true;
}

double volume(const Shape& shape) { return shape.box_size_m[0] * shape.box_size_m[1] * shape.box_size_m[2]; }

// A solid box of unit mass: (y² + z²)/12 about x, and so on.
Eigen::Matrix3d inertia_per_kg(const Shape& shape) {
  const Eigen::Vector3d squared = to_eigen(shape.box_size_m).cwiseAbs2();
  return Eigen::Vector3d(squared.y() + squared.z(), squared.x() + squared.z(), squared.x() + squared.y()).asDiagonal() *
         (1.0 / 12.0);
}

// The space diagonal: no two points of the box are farther apart, so a face has ended by then.
double plane_extent(const Shape& shape) { return to_eigen(shape.box_size_m).norm(); }

// A face's plane outlives the face: a finger that slides off an edge would keep feeling the face's full press until
// the next world frame (up to a period), as if the face went on. The plane belongs to the face whose normal is nearest
// its own. While `around_m` lies over that face (outside the box with the face's point nearest), on it, or deep inside
// the box (the world chose the face), the plane stays as it came, so everything the interpolation and the local model
// do on a face is unchanged. Once past the face's rim the plane is the box's at its point nearest `around_m`: an edge
// or corner (normal from that point to `around_m`), or the neighbouring face it went round to, or lies on.
void retake(ShapePlane& plane, const Eigen::Vector3d& around_m) {
  const Eigen::Vector3d local_m = plane.axes.transpose() * (around_m - plane.com_m);  // box frame
  const Eigen::Vector3d half_m = half_sizes(plane.shape);
  // The plane's face: the one whose normal is nearest the plane's. The plane is that face's as the interpolation or
  // the local model moved it, which may turn it off the box's axis a little (the local model's blend toward a new
  // frame); an edge's plane counts as its nearer face's, as the world gave it while the proxy stays over that face.
  const Eigen::Vector3d normal_local = plane.axes.transpose() * plane.normal;
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
    plane.normal = plane.axes * (offset_local_m / distance_m);
    plane.point_m = plane.com_m + plane.axes * nearest_local_m;
    return;
  }
  // On the surface (where the god-object leaves a proxy) or inside (the box moved onto it). A proxy deep inside keeps
  // the plane (the world chose the face; a plane blending from a face's toward the edge's the finger slid past sinks
  // into the box, and lets the finger go, as it should). A proxy on the plane's own face keeps the plane only within
  // 1° of the face, and otherwise gets the face's own plane: a blend between an edge's plane and a face's kept under a
  // proxy on the face would carry the proxy off the face, the next tick would bring it back, and so on, a hop every
  // tick. A proxy on another face (it went round an edge) gets that face: of the faces it is on, the one nearest the
  // plane's normal.
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
  plane.normal = best_side * plane.axes.col(best_axis);
  plane.point_m = plane.com_m + plane.axes * on_face_m;
}

int nearest_faces(const Shape& shape, const Eigen::Vector3d& q, double tolerance_m,
                  std::array<Eigen::Vector3d, 3>& normals) {
  const Eigen::Vector3d gap_m = half_sizes(shape) - q.cwiseAbs();  // negative along an axis the point is outside of
  if (gap_m.minCoeff() < -tolerance_m) return 0;
  const double nearest_m = gap_m.minCoeff();
  int count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (gap_m[axis] > nearest_m + tolerance_m) continue;
    normals[static_cast<std::size_t>(count)] = Eigen::Vector3d::Zero();
    normals[static_cast<std::size_t>(count)][axis] = q[axis] >= 0.0 ? 1.0 : -1.0;
    ++count;
  }
  return count;
}

// The face that looks along −n, the one whose axis is nearest n, and its four corners.
int support_corners(const Shape& shape, const Eigen::Matrix3d& axes, const Eigen::Vector3d& n,
                    std::array<Eigen::Vector3d, 4>& corners) {
  const Eigen::Vector3d half_m = half_sizes(shape);
  int down = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::fabs(axes.col(k).dot(n)) > std::fabs(axes.col(down).dot(n))) down = k;
  }
  const double side = axes.col(down).dot(n) > 0.0 ? -1.0 : 1.0;
  const int a = (down + 1) % 3, b = (down + 2) % 3;
  for (int c = 0; c < 4; ++c) {
    corners[static_cast<std::size_t>(c)] = side * half_m[down] * axes.col(down) +
                                           ((c & 1) != 0 ? 1.0 : -1.0) * half_m[a] * axes.col(a) +
                                           ((c & 2) != 0 ? 1.0 : -1.0) * half_m[b] * axes.col(b);
  }
  return 4;
}

// The eight corners (its edges are edges).
int contact_samples(const Shape& shape, ContactSamples& samples) {
  const Eigen::Vector3d half_m = half_sizes(shape);
  for (int c = 0; c < 8; ++c) {
    samples[static_cast<std::size_t>(c)] = {
        Eigen::Vector3d((c & 1) ? half_m.x() : -half_m.x(), (c & 2) ? half_m.y() : -half_m.y(),
                        (c & 4) ? half_m.z() : -half_m.z()),
        0.0};
  }
  return 8;
}

// The twelve edges, four along each axis, with the normals of the two faces that meet at each.
int contact_edges(const Shape& shape, ContactEdges& edges) {
  const Eigen::Vector3d half_m = half_sizes(shape);
  int count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int edge = 0; edge < 4; ++edge) {
      Eigen::Vector3d from_m;
      from_m[axis] = -half_m[axis];
      from_m[a] = (edge & 1) ? half_m[a] : -half_m[a];
      from_m[b] = (edge & 2) ? half_m[b] : -half_m[b];
      Eigen::Vector3d to_m = from_m;
      to_m[axis] = half_m[axis];
      Eigen::Vector3d face_a = Eigen::Vector3d::Zero(), face_b = Eigen::Vector3d::Zero();
      face_a[a] = (edge & 1) ? 1.0 : -1.0;
      face_b[b] = (edge & 2) ? 1.0 : -1.0;
      edges[static_cast<std::size_t>(count++)] = {from_m, to_m, 0.0, face_a, face_b};
    }
  }
  return count;
}

constexpr std::string_view kKeys[] = {"size_m"};

}  // namespace

const ShapeKindOps kBoxOps{
    .name = "box",
    .traits = {.carries_axes = true, .flat_faces = true, .round = false, .normal_through_core = false, .convex = true},
    .keys = kKeys,
    .parse = parse,
    .problem = problem,
    .nearest = nearest,
    .support = support,
    .bounds_half = bounds_half,
    .segment_enters = segment_enters,
    .volume = volume,
    .inertia_per_kg = inertia_per_kg,
    .plane_extent = plane_extent,
    .describes_within = plane_extent,
    .retake = retake,
    .nearest_faces = nearest_faces,
    .support_corners = support_corners,
    .contact_samples = contact_samples,
    .contact_edges = contact_edges,
};

}  // namespace impetus::shape_detail
