// SPDX-License-Identifier: Apache-2.0
#include "world_manager/features/feature_extractor.h"

#include <algorithm>
#include <cmath>

namespace impetus {

namespace {

// The grid cell should hold a few objects and cover the base reach: the larger of the reach radius and the median
// object size keeps both the number of cells per query and the objects per cell small.
double choose_cell_size_m(const Scene& scene) {
  std::vector<double> extents_m;
  extents_m.reserve(scene.objects.size());
  for (const SceneObject& object : scene.objects) {
    extents_m.push_back(largest_extent_m(object.shape));
  }
  double median_m = 0.0;
  if (!extents_m.empty()) {
    auto middle = extents_m.begin() + static_cast<std::ptrdiff_t>(extents_m.size() / 2);
    std::nth_element(extents_m.begin(), middle, extents_m.end());
    median_m = *middle;
  }
  return std::max(scene.haptic.reach_radius_m, median_m);
}

// Faces nearer than this to the same query are one feature: a proxy the servo put on a box's edge or in a corner is
// exact only to rounding (~1e-17 m at these coordinates), far below any modelled feature (0.1 mm, SceneLimits).
constexpr double kFaceTie_m = 1e-9;
// How far past a tied face its outside is probed for another object: far beyond the tie's rounding, far below the
// smallest object (0.1 mm), so a neighbour whose face touches this one, or lies within a micrometre of it, occupies it.
constexpr double kOutsideProbe_m = 1e-6;

bool nearer(const ReachCandidate& a, const ReachCandidate& b) {
  if (a.surface.signed_distance_m != b.surface.signed_distance_m) {
    return a.surface.signed_distance_m < b.surface.signed_distance_m;
  }
  return a.object_id < b.object_id;
}

}  // namespace

FeatureExtractor::FeatureExtractor(const Scene& scene) : scene_(scene), grid_(choose_cell_size_m(scene)) {}

Eigen::AlignedBox3d FeatureExtractor::swept_bounds(std::size_t id, const ObjectState& state,
                                                   double world_period_s) const {
  Eigen::AlignedBox3d box = world_bounds(scene_.objects[id].shape, state.pose);
  // Sweeping each box by its own motion in one period lets the query use only the finger's part of the reach.
  const double sweep_m = state.velocity_mps.norm() * world_period_s;
  box.min().array() -= sweep_m;
  box.max().array() += sweep_m;
  return box;
}

void FeatureExtractor::index(std::span<const ObjectState> states, double world_period_s) {
  swept_bounds_.resize(states.size());
  fastest_mps_ = 0.0;
  largest_acceleration_mps2_ = 0.0;
  for (std::size_t i = 0; i < states.size(); ++i) {
    swept_bounds_[i] = swept_bounds(i, states[i], world_period_s);
    fastest_mps_ = std::max(fastest_mps_, states[i].velocity_mps.norm());
    largest_acceleration_mps2_ = std::max(largest_acceleration_mps2_, states[i].acceleration_mps2.norm());
  }
  grid_.rebuild(swept_bounds_);
}

void FeatureExtractor::reindex(std::span<const ObjectState> states, double world_period_s,
                               std::span<const std::size_t> moved) {
  if (swept_bounds_.size() != states.size()) return index(states, world_period_s);
  largest_acceleration_mps2_ = 0.0;
  for (const std::size_t id : moved) {
    if (id >= states.size()) continue;
    swept_bounds_[id] = swept_bounds(id, states[id], world_period_s);
    fastest_mps_ = std::max(fastest_mps_, states[id].velocity_mps.norm());
    largest_acceleration_mps2_ = std::max(largest_acceleration_mps2_, states[id].acceleration_mps2.norm());
    grid_.update(static_cast<std::int32_t>(id), swept_bounds_[id]);
  }
}

void FeatureExtractor::within_reach(const ReachQuery& finger, std::span<const ObjectState> states,
                                    double world_period_s, std::vector<ReachCandidate>& out,
                                    FeatureMemory* memory) const {
  out.clear();
  const double finger_speed_mps = finger.velocity_mps.norm();
  const double base_reach_m = scene_.haptic.reach_radius_m + finger.reach_extra_m;
  // The time until the planes of this step are replaced at the finger: a world period, and the link's round trip.
  const double horizon_s = world_period_s + finger.round_trip_s;
  const double finger_reach_m = base_reach_m + finger_speed_mps * horizon_s;
  // The grid holds bounds swept over one period: over a round trip any object may come further by its speed.
  const double query_m = finger_reach_m + (finger.round_trip_s > 0.0 ? fastest_mps_ * finger.round_trip_s : 0.0) +
                         0.5 * largest_acceleration_mps2_ * horizon_s * horizon_s;
  const Eigen::AlignedBox3d query(finger.position_m.array() - query_m, finger.position_m.array() + query_m);
  grid_.query(query, candidate_ids_);

  for (std::int32_t id : candidate_ids_) {
    const ObjectState& state = states[static_cast<std::size_t>(id)];
    const Shape& shape = scene_.objects[static_cast<std::size_t>(id)].shape;
    SurfacePoint surface = nearest_surface_point(shape, state.pose, finger.position_m);
    const ShapeTraits& kind = traits(shape.kind);
    if (kind.flat_faces && surface.signed_distance_m <= kFaceTie_m) {
      surface = open_face(id, surface, finger.position_m, states);
    }
    // The frame the face is remembered in: the body's, so a face turns with it; a ball's surface does not change when
    // it spins (a rolling ball turns half a revolution in a period), so a ball's is the world's axes about its centre.
    BodyPose frame = state.pose;
    if (kind.round) frame.orientation = Eigen::Quaterniond::Identity();
    const Eigen::Vector3d query_local_m = frame.orientation.conjugate() * (finger.position_m - frame.position_m);
    if (memory != nullptr && kind.convex) {
      // Inside, or swept over within the step: keep the face of the last step, if the query is behind it
      // (feature_memory.h).
      if (const FeatureMemory::Face* kept = memory->previous(id); kept != nullptr) {
        const SurfacePoint face = supporting_plane(shape, frame, finger.position_m, kept->normal_body);
        // Past the middle: the query is beyond the object's centre along the kept normal, where the nearest face is
        // the far one. Inside a flat-faced body any other face than the one it met is a face the object brought over
        // the query (its faces are discrete); a curved surface turns continuously under a query that slides over it,
        // so there only past the middle is the far side. Swept over: outside now, past the middle, through the
        // object since.
        const bool past_middle = kept->normal_body.dot(query_local_m) < 0.0;
        const bool inside = surface.signed_distance_m < 0.0 && (kind.flat_faces || past_middle);
        const bool swept = surface.signed_distance_m >= 0.0 && past_middle &&
                           segment_enters_body(shape, kept->query_body_m, query_local_m);
        if (face.signed_distance_m < 0.0 && face.point_m.allFinite() && face.normal.allFinite() && (inside || swept)) {
          surface = face;
        }
      }
    }
    // docs/architecture.md §1.1 step 4 (header): the travel of both over H, and the object's at its acceleration.
    const double reach_m = base_reach_m + (finger_speed_mps + state.velocity_mps.norm()) * horizon_s +
                           0.5 * state.acceleration_mps2.norm() * horizon_s * horizon_s;
    // A NaN distance fails this test: a broken object gives no plane rather than a frame the haptic side rejects.
    if (surface.signed_distance_m <= reach_m && surface.point_m.allFinite() && surface.normal.allFinite()) {
      out.push_back({id, surface});
      if (memory != nullptr) memory->remember(id, {frame.orientation.conjugate() * surface.normal, query_local_m});
    }
  }

  if (scene_.floor.present) {
    // The floor is the half-space z <= height: nearest point straight below (or above) the finger, normal +z.
    const double height_m = scene_.floor.height_m;
    const double distance_m = finger.position_m.z() - height_m;
    if (distance_m <= finger_reach_m) {
      const Eigen::Vector3d point_m(finger.position_m.x(), finger.position_m.y(), height_m);
      out.push_back({scene_.floor_object_id(), {point_m, Eigen::Vector3d::UnitZ(), distance_m}});
    }
  }
  std::sort(out.begin(), out.end(), nearer);
}

bool FeatureExtractor::occupied(const Eigen::Vector3d& point_m, std::int32_t self,
                                std::span<const ObjectState> states) const {
  if (scene_.floor.present && point_m.z() < scene_.floor.height_m) return true;
  for (std::int32_t other : candidate_ids_) {
    if (other == self) continue;
    const auto i = static_cast<std::size_t>(other);
    if (nearest_surface_point(scene_.objects[i].shape, states[i].pose, point_m).signed_distance_m < 0.0) return true;
  }
  return false;
}

SurfacePoint FeatureExtractor::open_face(std::int32_t id, const SurfacePoint& nearest,
                                             const Eigen::Vector3d& query_m,
                                             std::span<const ObjectState> states) const {
  const auto i = static_cast<std::size_t>(id);
  const Shape& shape = scene_.objects[i].shape;
  const BodyPose& pose = states[i].pose;
  const Eigen::Vector3d query_body_m = pose.orientation.conjugate() * (query_m - pose.position_m);
  std::array<Eigen::Vector3d, 3> faces;
  const int count = nearest_faces_body(shape, query_body_m, kFaceTie_m, faces);
  if (count == 0) return nearest;
  // On a face within rounding, outside it or in: its plane, not the direction of a rounding-sized offset.
  if (count == 1) return supporting_plane(shape, pose, query_m, faces[0]);
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3d& normal = faces[static_cast<std::size_t>(k)];
    // Just outside face k and just inside the other tied faces: the region only face k bounds. A neighbour's face may
    // end exactly at the query (a face half covered, half open), so the probe is also moved half as far along the
    // face's two tangents both ways: the face is open if any of the five points is free.
    Eigen::Vector3d direction = normal;
    for (int j = 0; j < count; ++j) {
      if (j != k) direction -= faces[static_cast<std::size_t>(j)];
    }
    const Eigen::Vector3d base_m = kOutsideProbe_m * direction.normalized();
    const Eigen::Vector3d tangent_a = normal.unitOrthogonal();
    const Eigen::Vector3d tangent_b = normal.cross(tangent_a);
    for (const Eigen::Vector2d& side : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(1, -1),
                                       Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1)}) {
      const Eigen::Vector3d offset_body_m =
          base_m + 0.5 * kOutsideProbe_m * (side.x() * tangent_a + side.y() * tangent_b);
      if (!occupied(query_m + pose.orientation * offset_body_m, id, states)) {
        return supporting_plane(shape, pose, query_m, normal);
      }
    }
  }
  return nearest;
}

Plane FeatureExtractor::make_plane(const ReachCandidate& candidate, std::span<const ObjectState> states) const {
  Plane plane;
  plane.object_id = candidate.object_id;
  plane.point_m = to_vec3(candidate.surface.point_m);
  plane.normal = to_vec3(candidate.surface.normal);
  const bool is_floor = candidate.object_id == scene_.floor_object_id();
  const Material& material =
      is_floor ? scene_.floor.material : scene_.objects[static_cast<std::size_t>(candidate.object_id)].material;
  plane.static_friction = material.static_friction;
  plane.dynamic_friction = material.dynamic_friction;
  if (scene_.haptic.finger_material_given) {
    // The finger pad is one more material: combined like any two bodies (world_manager/scene.h).
    plane.static_friction = combine_friction(plane.static_friction, scene_.haptic.finger_material.static_friction);
    plane.dynamic_friction = combine_friction(plane.dynamic_friction, scene_.haptic.finger_material.dynamic_friction);
  }
  if (is_floor) {
    plane.com_m = plane.point_m;  // the floor has no centre of mass; it never moves, so any point on it serves
    return plane;
  }
  const ObjectState& state = states[static_cast<std::size_t>(candidate.object_id)];
  const SceneObject& object = scene_.objects[static_cast<std::size_t>(candidate.object_id)];
  plane.flags = object.dynamic ? kPlaneDynamic : 0u;
  plane.shape = object.shape;
  if (traits(object.shape.kind).carries_axes) {
    const Eigen::Matrix3d axes = state.pose.orientation.toRotationMatrix();
    plane.body_axis_x = to_vec3(axes.col(0));
    plane.body_axis_y = to_vec3(axes.col(1));
  }
  plane.extent_m = plane_extent_m(object.shape);
  plane.com_m = to_vec3(state.pose.position_m);
  plane.velocity_mps = to_vec3(state.velocity_mps);
  plane.angular_velocity_radps = to_vec3(state.angular_velocity_radps);
  plane.inverse_mass_per_kg = state.inverse_mass_per_kg;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) plane.inverse_inertia_world[static_cast<std::size_t>(3 * r + c)] =
        state.inverse_inertia_world(r, c);
  }
  return plane;
}

std::uint32_t FeatureExtractor::extract(const ReachQuery& finger, std::span<const ObjectState> states,
                                        double world_period_s, std::array<Plane, kMaxPlanes>& planes,
                                        FeatureMemory* memory) const {
  within_reach(finger, states, world_period_s, reach_scratch_, memory);
  // Sorted nearest first, so a crowded neighbourhood keeps the kMaxPlanes planes the finger can touch soonest.
  const std::size_t count = std::min<std::size_t>(reach_scratch_.size(), kMaxPlanes);
  for (std::size_t i = 0; i < count; ++i) planes[i] = make_plane(reach_scratch_[i], states);
  return static_cast<std::uint32_t>(count);
}

}  // namespace impetus
