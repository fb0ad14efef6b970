// SPDX-License-Identifier: Apache-2.0
#include "world_manager/features/body_geometry.h"

#include <algorithm>
#include <cmath>

namespace impetus {

namespace {

// Below this distance from a shape's centre (or axis) the direction to the query point is numerically meaningless
// (1 nm, far under any modelled feature), so the fixed fallback direction is used instead.
constexpr double kDegenerateDistance_m = 1e-9;

// Sphere of `radius_m` about `centre_m`: the radial direction, also from inside.
SurfacePoint nearest_on_sphere(const Eigen::Vector3d& centre_m, double radius_m, const Eigen::Vector3d& query_m,
                               const Eigen::Vector3d& fallback_normal) {
  const Eigen::Vector3d offset_m = query_m - centre_m;
  const double distance_m = offset_m.norm();
  const Eigen::Vector3d normal = distance_m > kDegenerateDistance_m ? Eigen::Vector3d(offset_m / distance_m)
                                                                    : fallback_normal;
  return {centre_m + radius_m * normal, normal, distance_m - radius_m};
}

SurfacePoint nearest_on_box(const Eigen::Vector3d& half_m, const Eigen::Vector3d& q) {
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

SurfacePoint nearest_on_cylinder(double radius_m, double half_length_m, const Eigen::Vector3d& q) {
  const double radial_m = std::hypot(q.x(), q.y());
  const Eigen::Vector2d radial_dir =
      radial_m > kDegenerateDistance_m ? Eigen::Vector2d(q.x() / radial_m, q.y() / radial_m) : Eigen::Vector2d(1, 0);
  const bool outside = radial_m > radius_m || std::abs(q.z()) > half_length_m;
  if (outside) {
    const double clamped_radial_m = std::min(radial_m, radius_m);
    const Eigen::Vector3d clamped(radial_dir.x() * clamped_radial_m, radial_dir.y() * clamped_radial_m,
                                  std::clamp(q.z(), -half_length_m, half_length_m));
    const Eigen::Vector3d offset_m = q - clamped;
    const double distance_m = offset_m.norm();
    return {clamped, offset_m / distance_m, distance_m};
  }
  const double side_gap_m = radius_m - radial_m;
  const double cap_gap_m = half_length_m - std::abs(q.z());
  if (cap_gap_m < side_gap_m) {
    const double side = q.z() >= 0.0 ? 1.0 : -1.0;
    return {Eigen::Vector3d(q.x(), q.y(), side * half_length_m), Eigen::Vector3d(0, 0, side), -cap_gap_m};
  }
  const Eigen::Vector3d normal(radial_dir.x(), radial_dir.y(), 0.0);
  return {Eigen::Vector3d(radial_dir.x() * radius_m, radial_dir.y() * radius_m, q.z()), normal, -side_gap_m};
}

}  // namespace

SurfacePoint nearest_surface_point_body(const Shape& shape, const Eigen::Vector3d& query_m) {
  switch (shape.kind) {
    case ShapeKind::sphere:
      return nearest_on_sphere(Eigen::Vector3d::Zero(), shape.radius_m, query_m, Eigen::Vector3d::UnitZ());
    case ShapeKind::box:
      return nearest_on_box(0.5 * to_eigen(shape.box_size_m), query_m);
    case ShapeKind::capsule: {
      // A capsule is the set of points within radius of its axis segment: a sphere about the nearest axis point.
      const double half_length_m = 0.5 * shape.length_m;
      const Eigen::Vector3d axis_point_m(0.0, 0.0, std::clamp(query_m.z(), -half_length_m, half_length_m));
      return nearest_on_sphere(axis_point_m, shape.radius_m, query_m, Eigen::Vector3d::UnitX());
    }
    case ShapeKind::cylinder:
      return nearest_on_cylinder(shape.radius_m, 0.5 * shape.length_m, query_m);
  }
  return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.0};
}

int nearest_box_faces(const Eigen::Vector3d& half_m, const Eigen::Vector3d& q, double tolerance_m,
                      std::array<Eigen::Vector3d, 3>& normals) {
  const Eigen::Vector3d gap_m = half_m - q.cwiseAbs();  // negative along an axis the point is outside of
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

SurfacePoint nearest_surface_point(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m) {
  const Eigen::Vector3d query_body_m = pose.orientation.conjugate() * (query_m - pose.position_m);
  const SurfacePoint body = nearest_surface_point_body(shape, query_body_m);
  return {pose.orientation * body.point_m + pose.position_m, pose.orientation * body.normal, body.signed_distance_m};
}

SurfacePoint supporting_plane(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m,
                              const Eigen::Vector3d& normal_body) {
  const Eigen::Vector3d& n = normal_body;
  double support_m = 0.0;  // h(n) about the body origin
  switch (shape.kind) {
    case ShapeKind::sphere:
      support_m = shape.radius_m;
      break;
    case ShapeKind::box:
      support_m = 0.5 * (to_eigen(shape.box_size_m).array() * n.array().abs()).sum();
      break;
    case ShapeKind::capsule:  // the axis segment's support plus the radius
      support_m = 0.5 * shape.length_m * std::abs(n.z()) + shape.radius_m;
      break;
    case ShapeKind::cylinder:  // a cap's rim: the disc's support plus the half length along the axis
      support_m = 0.5 * shape.length_m * std::abs(n.z()) + shape.radius_m * std::hypot(n.x(), n.y());
      break;
  }
  const Eigen::Vector3d query_body_m = pose.orientation.conjugate() * (query_m - pose.position_m);
  const double signed_distance_m = n.dot(query_body_m) - support_m;
  // The query projected onto the plane; for a sphere its support point r·n instead, since a sphere's plane carries
  // the centre as point − r·normal (contract/frames.h kPlaneSphere).
  const Eigen::Vector3d point_body_m =
      shape.kind == ShapeKind::sphere ? Eigen::Vector3d(support_m * n) : Eigen::Vector3d(query_body_m - signed_distance_m * n);
  return {pose.orientation * point_body_m + pose.position_m, pose.orientation * n, signed_distance_m};
}

bool segment_enters_body(const Shape& shape, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m) {
  auto distance_at = [&](double t) { return nearest_surface_point_body(shape, from_m + t * (to_m - from_m)).signed_distance_m; };
  if (distance_at(0.0) < 0.0 || distance_at(1.0) < 0.0) return true;
  // Golden-section search for the least distance on [0, 1]; 60 iterations shrink the bracket by 0.618^60 ≈ 3e-13.
  constexpr double kInverseGolden = 0.6180339887498949;
  double lo = 0.0;
  double hi = 1.0;
  double a = hi - kInverseGolden * (hi - lo);
  double b = lo + kInverseGolden * (hi - lo);
  double fa = distance_at(a);
  double fb = distance_at(b);
  for (int i = 0; i < 60; ++i) {
    if (fa < 0.0 || fb < 0.0) return true;
    if (fa < fb) {
      hi = b;
      b = a;
      fb = fa;
      a = hi - kInverseGolden * (hi - lo);
      fa = distance_at(a);
    } else {
      lo = a;
      a = b;
      fa = fb;
      b = lo + kInverseGolden * (hi - lo);
      fb = distance_at(b);
    }
  }
  return fa < 0.0 || fb < 0.0;
}

double plane_extent_m(const Shape& shape) {
  switch (shape.kind) {
    case ShapeKind::box:
      return to_eigen(shape.box_size_m).norm();
    case ShapeKind::sphere:
    case ShapeKind::capsule:
    case ShapeKind::cylinder:
      return shape.radius_m;
  }
  return 0.0;
}

Eigen::AlignedBox3d world_bounds(const Shape& shape, const BodyPose& pose) {
  const Eigen::Matrix3d rotation = pose.orientation.toRotationMatrix();
  Eigen::Vector3d half_m = Eigen::Vector3d::Zero();
  switch (shape.kind) {
    case ShapeKind::sphere:
      half_m.setConstant(shape.radius_m);
      break;
    case ShapeKind::box:
      half_m = rotation.cwiseAbs() * (0.5 * to_eigen(shape.box_size_m));
      break;
    case ShapeKind::capsule:
      half_m = (0.5 * shape.length_m) * rotation.col(2).cwiseAbs() + Eigen::Vector3d::Constant(shape.radius_m);
      break;
    case ShapeKind::cylinder: {
      // A disc of radius r with unit normal u extends r·sqrt(1 − u_i²) along world axis i.
      const Eigen::Vector3d axis = rotation.col(2);
      for (int i = 0; i < 3; ++i) {
        half_m[i] = 0.5 * shape.length_m * std::abs(axis[i]) +
                    shape.radius_m * std::sqrt(std::max(0.0, 1.0 - axis[i] * axis[i]));
      }
      break;
    }
  }
  return {pose.position_m - half_m, pose.position_m + half_m};
}

}  // namespace impetus
