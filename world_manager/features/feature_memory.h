// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which face of each object a query point met in the last world step (its contact feature), carried to the next step.
//
// Why: the nearest face of a body that has moved more than half its size onto a point is its far face. A finger held
// still while an object arrives faster than that (half a 5 cm cube in one 20 Hz period is 0.5 m/s) would get the far
// face's plane: the proxy jumps across, the finger is pulled into the object and the object passes through. So a
// point on an object's far side keeps the face it had in the last step, the side it was on, as the object's supporting
// plane with that body-frame normal (common/shape/shape.h supporting_plane). The far side: inside a box, any face but
// that one (a box's faces are discrete); inside a curved surface, which turns continuously under a finger sliding over
// it, past the middle (beyond the centre along the kept normal); outside, past the middle with the object swept over
// the point within the step (faster than its own size per period: the segment from where the point was in the body's
// frame a step ago to where it is now passes through the body). Any other point takes the nearest face, as does an
// object that had no face for this query in the last step.
//
// One memory per query point (the plane query around the proxy; position coupling's finger). Not thread-safe.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace impetus {

class FeatureMemory {
 public:
  // Starts a world step: what was remembered in the step before becomes `previous`.
  void begin_step(std::size_t object_count) {
    if (faces_.size() != object_count) {
      faces_.assign(object_count, Face{});
      step_.assign(object_count, 0);
    }
    ++step_index_;
  }
  // What object `id` had for this query in a step: its face's outward normal and the query, both in the body frame
  // (a sphere's: in world axes about its centre, as its surface does not turn when it spins).
  struct Face {
    Eigen::Vector3d normal_body = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d query_body_m = Eigen::Vector3d::Zero();
  };

  // The face object `id` had in the previous step, or nullptr.
  const Face* previous(std::int32_t id) const {
    const auto i = static_cast<std::size_t>(id);
    return id >= 0 && i < step_.size() && step_[i] + 1 == step_index_ ? &faces_[i] : nullptr;
  }
  void remember(std::int32_t id, const Face& face) {
    const auto i = static_cast<std::size_t>(id);
    if (id < 0 || i >= step_.size()) return;
    faces_[i] = face;
    step_[i] = step_index_;
  }

 private:
  std::vector<Face> faces_;
  std::vector<std::uint64_t> step_;  // the step each normal was remembered in; 0: never
  std::uint64_t step_index_ = 1;     // the first begin_step makes it 2, so no entry counts as the previous step's
};

}  // namespace impetus
