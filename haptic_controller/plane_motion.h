// SPDX-License-Identifier: Apache-2.0
#pragma once
// How the planes move on the haptic side between world frames (docs/architecture.md §1.2 step 2), per coupling:
//   InterpolatedPlanes  impulse and position coupling: paper §3.2's interpolation between frames i−1 and i;
//   LocalDynamics       local coupling (paper §6.3): frame i's planes carried by a local rigid-body model that the
//                       finger's own reaction moves tick by tick (local_dynamics.h).
// The servo picks one from the coupling each frame names, and otherwise only calls this interface.
//
// Owned by the servo thread; implementations are allocation-free.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"
#include "haptic_controller/impulse_accumulator.h"
#include "haptic_controller/plane_matching.h"
#include "haptic_controller/proxy_projection.h"

#include <Eigen/Core>

namespace impetus {

class PlaneMotion {
 public:
  virtual ~PlaneMotion() = default;

  // Frame i arrived. `previous` is frame i−1 of the same world session (frame i itself when a session starts),
  // `displayed` the planes the finger felt in the last tick (nullptr when a session starts), `proxy_m` its proxy.
  virtual void on_frame(const PlaneFrame& previous, const PlaneFrame& frame, const PlaneSet* displayed,
                        const Eigen::Vector3d& proxy_m) = 0;
  // The planes of a tick dt_s after the last, at interpolation weight w (§3.2), turning about `pivot_m` (the last
  // proxy). `stale`: the world stopped sending frames, and the planes hold still.
  virtual void planes_for_tick(double w, double dt_s, bool stale, const Eigen::Vector3d& pivot_m, PlaneSet& out) = 0;
  // The share of the explicit contact force to render when the planes give way within the tick (≤ 1).
  virtual double yield_scale(const PlaneSet&, const ProxySolution&, const Eigen::Vector3d&, double, double,
                             double) const {
    return 1.0;
  }
  // This tick's reaction, shared among the touched objects (§3.4).
  virtual void take_shares(const ImpulseShare*, int) {}
  // At the last frame: how far (m) the planes the finger felt and the world's new ones disagreed at the proxy.
  virtual double frame_disagreement_m() const { return 0.0; }
};

// Paper §3.2 with the rules of plane_interpolator.h. Keeps copies of the two frames it interpolates between.
class InterpolatedPlanes final : public PlaneMotion {
 public:
  void on_frame(const PlaneFrame& previous, const PlaneFrame& frame, const PlaneSet*, const Eigen::Vector3d&) override;
  void planes_for_tick(double w, double, bool, const Eigen::Vector3d& pivot_m, PlaneSet& out) override;

 private:
  PlaneFrame previous_{};
  PlaneFrame current_{};
  PlaneMatches matches_{};  // current_'s planes in previous_, paired once per frame
};

}  // namespace impetus
