// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/local_yield.h"

#include <algorithm>

namespace impetus {
namespace {

constexpr double kLast = kDentPatchSide - 1;  // the patch's last sample index

const Plane* frame_plane(const PlaneFrame& frame, std::int32_t object_id) {
  const std::uint32_t count = std::min(frame.plane_count, kMaxPlanes);
  for (std::uint32_t k = 0; k < count; ++k) {
    if (frame.planes[k].object_id == object_id) return &frame.planes[k];
  }
  return nullptr;
}

// The patch's surface under `at_m` (frames.h DentPatch): its point and unit outward normal there, bilinear between the
// samples. False when `at_m` lies beyond the patch's outer samples.
bool patch_plane(const DentPatch& patch, const Eigen::Vector3d& at_m, Eigen::Vector3d& point_m,
                 Eigen::Vector3d& normal) {
  const Eigen::Vector3d axis_x = to_eigen(patch.axis_x);
  const Eigen::Vector3d axis_y = to_eigen(patch.axis_y);
  const Eigen::Vector3d up = axis_x.cross(axis_y);
  const Eigen::Vector3d offset_m = at_m - to_eigen(patch.origin_m);
  const double u = offset_m.dot(axis_x) / patch.spacing_m;
  const double v = offset_m.dot(axis_y) / patch.spacing_m;
  if (!(u >= 0.0 && u <= kLast && v >= 0.0 && v <= kLast)) return false;
  const auto height = [&patch](double uu, double vv) {
    const double cu = std::clamp(uu, 0.0, kLast);
    const double cv = std::clamp(vv, 0.0, kLast);
    const auto i0 = static_cast<std::uint32_t>(std::min(cu, kLast - 1.0));
    const auto j0 = static_cast<std::uint32_t>(std::min(cv, kLast - 1.0));
    const double tu = cu - i0;
    const double tv = cv - j0;
    const auto at = [&patch](std::uint32_t i, std::uint32_t j) { return patch.height_m[j * kDentPatchSide + i]; };
    return (1.0 - tv) * ((1.0 - tu) * at(i0, j0) + tu * at(i0 + 1, j0)) +
           tv * ((1.0 - tu) * at(i0, j0 + 1) + tu * at(i0 + 1, j0 + 1));
  };
  // The slope by central differences half a sample each way, per metre.
  const double slope_x = (height(u + 0.5, v) - height(u - 0.5, v)) / patch.spacing_m;
  const double slope_y = (height(u, v + 0.5) - height(u, v - 0.5)) / patch.spacing_m;
  point_m = to_eigen(patch.origin_m) + u * patch.spacing_m * axis_x + v * patch.spacing_m * axis_y + height(u, v) * up;
  normal = (up - slope_x * axis_x - slope_y * axis_y).normalized();
  return true;
}

}  // namespace

void LocalYield::record(std::uint64_t tick, const Eigen::Vector3d& proxy_m, const ImpulseShare* shares, int count) {
  for (int s = 0; s < count; ++s) {
    const ImpulseShare& share = shares[s];
    if (!(share.yielding_Ns > 0.0)) continue;
    if (count_ == kMaxSamples) ++forgotten_;
    samples_[next_] = {tick, share.object_id, share.yielding_Ns, proxy_m};
    next_ = (next_ + 1) % kMaxSamples;
    count_ = std::min(count_ + 1, kMaxSamples);
  }
}

void LocalYield::yield_elastic(const PlaneFrame& frame, const Plane& sent, const Eigen::Vector3d& proxy_m,
                               const Eigen::Vector3d& finger_m, double stiffness_Npm, ContactPlane& plane) {
  plane.normal = to_eigen(sent.normal);
  plane.point_m = to_eigen(sent.point_m);
  if (frame.dent_patch.object_id == plane.object_id) {
    patch_plane(frame.dent_patch, proxy_m, plane.point_m, plane.normal);
  }
  // The finger's spring k and the surface's compliance c in series: with the surface in by D under a push F,
  // F = k·(p − D) and D = c·F, so D = c·k·p / (1 + c·k), p how far the finger is below the frame's surface. Solved
  // within the tick, not from the last tick's force: with c·k above 1 (a soft gel under a stiff spring) that lag
  // would ring.
  const double below_m = (plane.point_m - finger_m).dot(plane.normal);
  if (!(below_m > 0.0) || !(stiffness_Npm > 0.0)) return;
  const double ck = sent.yield_compliance_mpN * stiffness_Npm;
  const double in_m = std::min(below_m * ck / (1.0 + ck), sent.yield_room_m);
  plane.point_m -= in_m * plane.normal;
}

void LocalYield::apply(const PlaneFrame& frame, std::uint64_t haptic_session, const Eigen::Vector3d& proxy_m,
                       const Eigen::Vector3d& finger_m, double stiffness_Npm, PlaneSet& planes) const {
  const std::uint64_t applied_tick = frame.report_session_applied == haptic_session ? frame.report_tick_applied : 0;
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (!plane.deformable()) continue;
    const Plane* sent = frame_plane(frame, plane.object_id);
    if (sent == nullptr) continue;
    if (sent->yield_compliance_mpN > 0.0) {
      yield_elastic(frame, *sent, proxy_m, finger_m, stiffness_Npm, plane);
      continue;
    }
    if (!(plane.yield_depth_mpNs > 0.0) || !(plane.yield_radius_m > 0.0)) continue;
    const double radius2_m2 = plane.yield_radius_m * plane.yield_radius_m;
    // Σ e_k·w(|x_k − proxy|) and its gradient in the proxy, Σ e_k·(−2/a²)·(proxy − x_k) over the pad, newest first,
    // down to the applied report.
    double pending_Ns = 0.0;
    Eigen::Vector3d pending_gradient_Nspm = Eigen::Vector3d::Zero();
    for (std::size_t n = 1; n <= count_; ++n) {
      const Sample& sample = samples_[(next_ + kMaxSamples - n) % kMaxSamples];
      if (sample.tick <= applied_tick) break;
      if (sample.object_id != plane.object_id) continue;
      const Eigen::Vector3d from_m = proxy_m - sample.at_m;
      const double weight = 1.0 - from_m.squaredNorm() / radius2_m2;
      if (!(weight > 0.0)) continue;
      pending_Ns += sample.yielding_Ns * weight;
      pending_gradient_Nspm -= (2.0 * sample.yielding_Ns / radius2_m2) * from_m;
    }
    plane.normal = to_eigen(sent->normal);
    plane.point_m = to_eigen(sent->point_m);
    // The surface under the proxy from the frame's heights, where it has them for this object; else the plane sent.
    if (frame.dent_patch.object_id == plane.object_id) {
      patch_plane(frame.dent_patch, proxy_m, plane.point_m, plane.normal);
    }
    const double dent_m = sent->yield_depth_mpNs * pending_Ns;
    const double offset_m = std::min(dent_m, sent->yield_room_m);
    plane.point_m -= offset_m * plane.normal;
    // The pending dent's slope tilts the surface, as the frame's heights do: along the surface, the height falls by
    // ∇D, so the outward normal becomes n + ∇D (tangential part). A finger moving over clay it is still denting meets
    // the front wall of its own dent there, and the push it gives the wall (and so the dent) depends on that slope.
    // Where the floor stopped the dent, the surface is the floor's: flat.
    if (dent_m <= sent->yield_room_m) {
      const Eigen::Vector3d slope = sent->yield_depth_mpNs * pending_gradient_Nspm;
      plane.normal = (plane.normal + slope - slope.dot(plane.normal) * plane.normal).normalized();
    }
  }
}

}  // namespace impetus
