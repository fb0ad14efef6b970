// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/local_yield.h"

#include <algorithm>

namespace impetus {
namespace {

const Plane* frame_plane(const PlaneFrame& frame, std::int32_t object_id) {
  const std::uint32_t count = std::min(frame.plane_count, kMaxPlanes);
  for (std::uint32_t k = 0; k < count; ++k) {
    if (frame.planes[k].object_id == object_id) return &frame.planes[k];
  }
  return nullptr;
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

void LocalYield::apply(const PlaneFrame& frame, std::uint64_t haptic_session, const Eigen::Vector3d& proxy_m,
                       PlaneSet& planes) const {
  const std::uint64_t applied_tick = frame.report_session_applied == haptic_session ? frame.report_tick_applied : 0;
  for (std::uint32_t k = 0; k < planes.count; ++k) {
    ContactPlane& plane = planes.planes[k];
    if (!plane.deformable() || !(plane.yield_depth_mpNs > 0.0) || !(plane.yield_radius_m > 0.0)) continue;
    const Plane* sent = frame_plane(frame, plane.object_id);
    if (sent == nullptr) continue;
    const double radius2_m2 = plane.yield_radius_m * plane.yield_radius_m;
    double pending_Ns = 0.0;  // Σ e_k·w(|x_k − proxy|), newest first, down to the applied report
    for (std::size_t n = 1; n <= count_; ++n) {
      const Sample& sample = samples_[(next_ + kMaxSamples - n) % kMaxSamples];
      if (sample.tick <= applied_tick) break;
      if (sample.object_id != plane.object_id) continue;
      pending_Ns += sample.yielding_Ns * std::max(0.0, 1.0 - (sample.at_m - proxy_m).squaredNorm() / radius2_m2);
    }
    plane.normal = to_eigen(sent->normal);
    const double offset_m = std::min(sent->yield_depth_mpNs * pending_Ns, sent->yield_room_m);
    plane.point_m = to_eigen(sent->point_m) - offset_m * plane.normal;
  }
}

}  // namespace impetus
