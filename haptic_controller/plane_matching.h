// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which plane of one frame is which plane of another (paper §3.2 interpolates "each received plane"): an object can
// give several planes (a box seen at an edge), so a plane is named by (object_id, occurrence), the occurrence being
// its rank among the planes of the same object in its frame. Used wherever planes of two frames or ticks are paired:
// interpolation, the local model's blend, the servo's frame-boundary diagnostic. Allocation-free.

#include "common/contract/frames.h"
#include "haptic_controller/contact_plane.h"

#include <algorithm>
#include <array>
#include <cstdint>

namespace impetus {

inline std::uint32_t plane_count(const PlaneFrame& frame) { return std::min(frame.plane_count, kMaxPlanes); }
inline std::uint32_t plane_count(const PlaneSet& set) { return std::min(set.count, kMaxServoPlanes); }

// The rank of plane k among the planes of its object in `set`.
template <class Planes>
int occurrence_of(const Planes& set, std::uint32_t k) {
  int occurrence = 0;
  for (std::uint32_t q = 0; q < k; ++q) occurrence += set.planes[q].object_id == set.planes[k].object_id ? 1 : 0;
  return occurrence;
}

// Index in `set` of the `occurrence`-th plane of `object_id`, or −1.
template <class Planes>
int find_plane(const Planes& set, std::int32_t object_id, int occurrence) {
  const std::uint32_t count = plane_count(set);
  for (std::uint32_t k = 0; k < count; ++k) {
    if (set.planes[k].object_id == object_id && occurrence-- == 0) return static_cast<int>(k);
  }
  return -1;
}

// For each plane k of `current`, the index of the same plane in `previous` ((object_id, occurrence) as above), or −1:
// what interpolation needs every tick, found once per pair of frames.
struct PlaneMatches {
  std::array<std::int16_t, kMaxServoPlanes> previous_index{};
};
template <class Planes>
void match_planes(const Planes& previous, const Planes& current, PlaneMatches& out) {
  const std::uint32_t count = plane_count(current);
  for (std::uint32_t k = 0; k < count; ++k) {
    out.previous_index[k] =
        static_cast<std::int16_t>(find_plane(previous, current.planes[k].object_id, occurrence_of(current, k)));
  }
}

// The flip rule of interpolation (plane_interpolator.h): two normals more than 90° apart (cos < 0) are not blended,
// since the blend would pass through a vanishing normal and sweep the plane through the object; the whole plane
// switches from the old to the new at the midpoint of the world period instead.
inline constexpr double kMinBlendCosine = 0.0;
inline constexpr double kFlipSwitchWeight = 0.5;
inline bool normals_flip(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return from.dot(to) < kMinBlendCosine;
}
// Whether a flipped plane shows the new plane at interpolation weight w.
inline bool flip_switched(double w) { return !(w < kFlipSwitchWeight); }

}  // namespace impetus
