// SPDX-License-Identifier: Apache-2.0
#pragma once
// Paper §3.1 and docs/architecture.md §1.1 step 4: the planes of the objects near the finger.
//
// An object is *within reach* when its surface is at most
//     reach = base radius + (finger speed + object speed)·H + ½·|object acceleration|·H²,   H = T_w (+ round trip)
// from the finger (inside counts: the signed distance is negative), so nothing either of them can reach before the next
// world step's planes replace these at the finger is missed. The acceleration is the object's mean over the last step
// (ObjectState::acceleration_mps2): a cube sliding down a 25° ramp gains 3.3 m/s², and over a 50 ms link (H = 0.15 s)
// that is 3.7 cm the speed term alone leaves out, more than the finger's stiffness can take up. The floor
// (object_id = scene.floor_object_id()) and static objects give planes too.
//
// The extractor keeps a SpatialGrid of every object's bounding box swept by its own speed·T_w; index() builds it,
// reindex() moves the objects that moved in a world step, and extract() then only tests the objects in the cells
// around the finger.
//
// Touching boxes: a query on an edge or corner of a box (the proxy in a concave corner of boxes whose faces touch
// exactly) is equally near two or three of its faces. The face given is one whose outside is free space: a face
// pressed against another object or the floor is inside the scene's solid, not a surface the finger can meet, and its
// plane would take the place of the face the finger does meet (the proxy then slides along the seam into the box).
// Among free faces, or when none is, the lowest body axis is taken, as everywhere else.

#include "common/contract/frames.h"
#include "world_manager/scene.h"
#include "common/shape/shape.h"
#include "world_manager/features/feature_memory.h"
#include "world_manager/object_state.h"
#include "world_manager/features/spatial_grid.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace impetus {

// Where the planes are extracted around: the haptic proxy when the report has one (it never enters an object, so a
// finger pushed deep into a thin plate still gets the plate's near face), else the finger itself. `reach_extra_m`
// widens the reach by how far the finger is from that point, so nothing between proxy and finger is missed.
// `round_trip_s` is the link's round trip as the haptic side measured it (HapticReport::link_round_trip_s): the
// planes reach the finger that much later than a world period after the finger was where the query says, so the
// reach covers the travel over T_w + round trip.
struct ReachQuery {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  double reach_extra_m = 0.0;
  double round_trip_s = 0.0;
};

// One object within reach and its nearest surface point to the finger.
struct ReachCandidate {
  std::int32_t object_id = -1;
  SurfacePoint surface;
};

class FeatureExtractor {
 public:
  // Keeps a reference to `scene`, which must outlive the extractor.
  explicit FeatureExtractor(const Scene& scene);

  // Indexes every object; `states[i]` is scene object i. O(N).
  void index(std::span<const ObjectState> states, double world_period_s);
  // Re-indexes the objects in `moved` after a world step (the others have not moved since they were indexed).
  // O(moved).
  void reindex(std::span<const ObjectState> states, double world_period_s, std::span<const std::size_t> moved);

  // Every object (and the floor) within reach, nearest first (ties by id). `states` must be those last indexed.
  // With `memory` (feature_memory.h), a query inside an object that had a face in memory's previous step keeps that
  // face; every object within reach is remembered with the face it got.
  void within_reach(const ReachQuery& finger, std::span<const ObjectState> states, double world_period_s,
                    std::vector<ReachCandidate>& out, FeatureMemory* memory = nullptr) const;

  // Fills planes[0..count) with the nearest kMaxPlanes objects within reach and returns count (paper §3.1); the
  // planes from count on are left as they were (the caller resets those it used before). `memory` as for within_reach.
  std::uint32_t extract(const ReachQuery& finger, std::span<const ObjectState> states, double world_period_s,
                        std::array<Plane, kMaxPlanes>& planes, FeatureMemory* memory = nullptr) const;

  // For tests and benchmarks: how many objects the last query tested exactly.
  std::size_t last_candidate_count() const { return candidate_ids_.size(); }

 private:
  Eigen::AlignedBox3d swept_bounds(std::size_t id, const ObjectState& state, double world_period_s) const;
  Plane make_plane(const ReachCandidate& candidate, std::span<const ObjectState> states) const;
  // The face of a box for a query on its surface within rounding: the face's own plane (not the direction of a
  // rounding-sized offset), and on an edge or corner a face whose outside is free (header: touching boxes).
  SurfacePoint open_face(std::int32_t id, const SurfacePoint& nearest, const Eigen::Vector3d& query_m,
                             std::span<const ObjectState> states) const;
  // Whether `point_m` lies inside the floor or an object of the last query other than `self`.
  bool occupied(const Eigen::Vector3d& point_m, std::int32_t self, std::span<const ObjectState> states) const;

  const Scene& scene_;
  SpatialGrid grid_;
  std::vector<Eigen::AlignedBox3d> swept_bounds_;
  // At least the fastest indexed object's speed (exact after index(), never lower after reindex()): a query over a
  // round trip widens its box by how far any object can come in it beyond the period its bounds are swept over.
  double fastest_mps_ = 0.0;
  // The largest acceleration among the bodies that moved in the last step (the others have none): the query's box
  // grows by its ½·a·H² as each object's reach does.
  double largest_acceleration_mps2_ = 0.0;
  mutable std::vector<std::int32_t> candidate_ids_;     // reused between queries: no allocation per step
  mutable std::vector<ReachCandidate> reach_scratch_;
};

}  // namespace impetus
