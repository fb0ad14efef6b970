// SPDX-License-Identifier: Apache-2.0
#pragma once
// A deformable surface between world frames (paper §6.4 with §6.3's idea; docs/deformation.md): taken again under the
// proxy every tick from the frame's heights around it (PlaneFrame::dent_patch), as a shape's plane is, since a finger
// moving over a dent leaves the plane of where it was; and yielding. The world
// dents it once per period from the push beyond yield it was sent, so a finger pressing on the frame's surface alone
// would meet clay that stands still for a period and then gives way by a step: it pushes harder than on clay that
// yields as it is pressed, and dents it deeper, the more so the slower the world. So each deformable plane is frame
// i's surface, not interpolated (frame i already shows every dent the world made from the reports up to the one it
// applied, PlaneFrame::report_tick_applied), moved in along its normal by what the push beyond yield of the later
// ticks will dent under the proxy, by the world's own law (world_manager/deform/deformable_material.h):
//     D = yield_depth_mpNs · Σ_{ticks k after the applied report} e_k · max(0, 1 − |x_k − proxy|² / a²)
// e_k the tick's push beyond yield into that object (ImpulseShare::yielding_Ns), x_k where it was given, a the pad's
// radius (Plane::yield_radius_m), and never beyond how far the surface there can still go (Plane::yield_room_m); and
// tilted by that dent's slope, n ← normalise(n + ∇D along the surface): a finger moving over clay it is still denting
// pushes against the front wall of its own dent. The world's next frame shows the same dent, made from the same
// pushes, to the difference between the pad's paraboloid and the world's cells (docs/deformation.md).
//
// An elastic surface (Plane::yield_compliance_mpN, world_manager/deform/elastic_membrane.h) springs back, and a
// gel's surface under a finger settles within milliseconds, far faster than a world period: under the frame's surface
// alone the finger would press on a surface that follows its push a period late, a delayed spring stiffer than the
// gel, which rings. So the world sends the surface without the static response to this finger's push, and the haptic
// side puts back the response to the push of this tick: the surface under the proxy goes in by c·F, c the pad's
// compliance, F the spring's force, solved within the tick (the spring and the gel in series). The frame carries the
// rest: the gel's motion, other fingers' dents, what the static response does not describe.
//
// Fixed capacity (kMaxSamples pushes: a second at 1 kHz with a finger on one surface, far more than a world period and
// a link's round trip); when full, the oldest is forgotten and counted (its dent then shows at the next frame).
// Allocation-free; owned by the servo thread.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/impulse_accumulator.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace impetus {

class LocalYield {
 public:
  static constexpr std::size_t kMaxSamples = 1024;

  // This tick's shares (ImpulseAccumulator::last_shares) at haptic tick `tick`, given at `proxy_m`.
  void record(std::uint64_t tick, const Eigen::Vector3d& proxy_m, const ImpulseShare* shares, int count);
  // Replaces each deformable plane of `planes` that yields (yield_depth_mpNs > 0) by its object's plane in `frame`,
  // moved in by the offset above about `proxy_m`, counting the pushes after the report `frame` says the world applied
  // (all of them if it applied none of `haptic_session`'s); and each elastic plane (yield_compliance_mpN > 0) by its
  // surface under the proxy moved in as far as the finger at `finger_m`, held by a spring of `stiffness_Npm`,
  // presses it (below).
  void apply(const PlaneFrame& frame, std::uint64_t haptic_session, const Eigen::Vector3d& proxy_m,
             const Eigen::Vector3d& finger_m, double stiffness_Npm, PlaneSet& planes) const;
  // A new world session or finger session: nothing recorded belongs to the planes to come.
  void clear() { count_ = 0; }

  std::uint64_t forgotten() const { return forgotten_; }

 private:
  static void yield_elastic(const PlaneFrame& frame, const Plane& sent, const Eigen::Vector3d& proxy_m,
                            const Eigen::Vector3d& finger_m, double stiffness_Npm, ContactPlane& plane);
  struct Sample {
    std::uint64_t tick = 0;
    std::int32_t object_id = -1;
    double yielding_Ns = 0.0;
    Eigen::Vector3d at_m = Eigen::Vector3d::Zero();
  };
  std::array<Sample, kMaxSamples> samples_{};
  std::size_t next_ = 0;   // where the next sample goes
  std::size_t count_ = 0;  // samples held, the newest just before next_
  std::uint64_t forgotten_ = 0;
};

}  // namespace impetus
