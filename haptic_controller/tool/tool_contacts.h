// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a rigid tool may touch the objects near it (docs/tool.md): the unilateral constraints the 6-DoF god-object
// (tool_proxy.h) holds the tool's proxy by.
//
// Every object a plane of the set carries is met by its contact features (common/shape/shape.h), both ways round:
// each of the tool's samples (corners, round cores) against the object's exact surface, each of the object's samples
// against the tool's exact surface, and each edge of the tool against each edge of the object where they cross
// (closest points inside both). A constraint is the half-space of the nearest surface at the pose now (its tangent
// plane there), or for crossing edges the plane across both (their cross product, where it lies in both edges'
// normal cones): the gap, the normal it pushes the tool along, and where on each body it acts. A plane without a
// shape (the floor) or with one this process has no features of (a mesh that is not small and convex, or not loaded
// here) is taken as the half-space it is, for the tool's samples only.
//
// Only constraints the tool can reach in this solve are listed: a sample whose gap exceeds how far that part of the
// tool can travel (a bound the caller gives, linear and angular) cannot become active. Frames: world, SI.
// Allocation-free; the tool's own samples are taken once, at construction.

#include "common/contract/tool.h"
#include "common/shape/shape.h"
#include "haptic_controller/contact_plane.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>

namespace impetus {
namespace tool_detail {
struct PlacedBody;  // a body placed in the world, as the contacts see it (tool_contacts.cpp)
}  // namespace tool_detail

// One unilateral constraint on the tool: gap_m + a·q ≥ 0 for a small move q = (δx, δθ) of the grip pose, with
// a = [normal; lever_m × normal] (lever from the grip's centre to tool_point_m).
struct ToolConstraint {
  std::int32_t plane = -1;      // index in the PlaneSet
  std::int32_t object_id = -1;  // that plane's object
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, the direction the contact pushes the tool
  Eigen::Vector3d tool_point_m = Eigen::Vector3d::Zero();    // on the tool's surface
  Eigen::Vector3d object_point_m = Eigen::Vector3d::Zero();  // on the object's surface
  double gap_m = 0.0;  // positive apart, negative overlapping
  // What met: a tool's sample against the object, an object's sample against the tool, or an edge of each; and
  // which (the tool's sample or edge, the object's sample or edge; −1 where none).
  enum class Kind : std::uint8_t { tool_sample, object_sample, edges };
  Kind kind = Kind::tool_sample;
  std::int16_t tool_feature = -1;
  std::int16_t object_feature = -1;
};

// The gap of a constraint whose features no longer meet (an edge pair that stopped crossing): never violated.
inline constexpr double kOpenGap_m = 1e9;

inline constexpr int kMaxToolConstraints = 96;

// How far a point of the tool `lever_m` from the grip's centre can travel in this solve: linear_m + angular_rad·lever.
struct ToolReach {
  double linear_m = 0.0;
  double angular_rad = 0.0;
  double at(double lever_m) const { return linear_m + angular_rad * lever_m; }
};

class ToolContacts {
 public:
  // Throws std::invalid_argument when the tool's shape has no contact samples (a mesh that is not small and convex, or
  // not loaded here) or is unusable.
  explicit ToolContacts(const ToolShape& tool);

  // The constraints at grip pose `grip` that `reach` can close, nearest first when there are more than
  // kMaxToolConstraints (the farthest dropped and counted in overflow()).
  int gather(const PlaneSet& planes, const BodyPose& grip, const ToolReach& reach);
  // Whether gathering again at the same pose with the reach's linear part grown by `growth_m` would list the same
  // constraints: every feature the last gather left out missed its reach by more than that.
  bool complete_for_growth(double growth_m) const { return missed_m_ > growth_m + kGrowthRounding_m; }
  // The same constraints (the same features of the same objects) measured again at grip pose `grip`: for the god-
  // object's later passes in a tick, whose moves stay within the reach they were gathered for.
  void refresh(const PlaneSet& planes, const BodyPose& grip, const ToolReach& reach);

  // Whether the tool can go straight from grip pose `from` to `to` touching nothing: no sample of the tool passes into
  // an object on its straight way, nor any object's sample into the tool (taken in the tool's frame, from where it
  // lies at `from` to where it lies at `to`), and none ends behind a plane without a shape. A box grown by a sample's
  // radius is grown square, so the answer errs toward "not clear".
  bool path_clear(const PlaneSet& planes, const BodyPose& from, const BodyPose& to);

  const ToolConstraint& operator[](int k) const { return constraints_[static_cast<std::size_t>(k)]; }
  int count() const { return count_; }
  std::uint64_t overflow() const { return overflow_; }

  const ToolShape& tool() const { return tool_; }
  // The tool's samples (shape frame), and the radius about the grip's centre that holds the tool.
  const ContactSamples& samples() const { return samples_; }
  int sample_count() const { return sample_count_; }
  double bounding_radius_m() const { return bounding_radius_m_; }

 private:
  void add(const ToolConstraint& constraint, double lever_m, const ToolReach& reach);
  BodyPose tool_pose(const BodyPose& grip) const;
  // An object's samples and edges, taken once per object and kept while its shape stays the same.
  struct CachedSamples {
    std::int32_t object_id = -1;
    Shape shape{};
    int count = 0;
    ContactSamples samples{};
    int edge_count = 0;
    ContactEdges edges{};
    double radius_m = 0.0;  // how far from its centre the object reaches
  };
  const CachedSamples& object_features(const ContactPlane& plane);
  tool_detail::PlacedBody placed_tool(const BodyPose& pose) const;
  static tool_detail::PlacedBody placed_object(const ContactPlane& plane, const CachedSamples& object);

  ToolShape tool_;
  ContactSamples samples_{};
  int sample_count_ = 0;
  ContactEdges edges_{};
  int edge_count_ = 0;
  double bounding_radius_m_ = 0.0;  // about the grip's centre
  double shape_radius_m_ = 0.0;     // about the tool shape's own centre
  std::array<ToolConstraint, kMaxToolConstraints> constraints_{};
  std::array<double, kMaxToolConstraints> slack_m_{};  // gap − reach at the constraint's lever (≤ 0)
  int count_ = 0;
  // The least amount by which a feature the last gather left out missed its reach (0 when that gather dropped
  // constraints for room: a larger reach may rank them differently).
  double missed_m_ = 0.0;
  // Rounding room for complete_for_growth: the reach grown and the bounds compared are each rounded once.
  static constexpr double kGrowthRounding_m = 1e-12;
  std::uint64_t overflow_ = 0;
  std::array<CachedSamples, kMaxServoPlanes> cache_{};
  int cached_ = 0;
  std::uint64_t cache_turns_ = 0;  // objects taken in once every slot was in use (the slot they took, round robin)
};

// The body pose a plane carries its shape at: a round body's centre (point − radius·normal), else its centre of mass
// and axes; and that centre alone.
BodyPose object_pose(const ContactPlane& plane);
Eigen::Vector3d object_centre(const ContactPlane& plane);

}  // namespace impetus
