// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/tool/tool_contacts.h"

#include "common/contract/rotation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

bool same_shape(const Shape& a, const Shape& b) { return std::memcmp(&a, &b, sizeof(Shape)) == 0; }

// The closest points of the segments p + s·d and q + t·e where they lie on both segments (0 ≤ s, t ≤ 1, to rounding):
// the unconstrained minimum of |p + s·d − q − t·e|², from its 2 × 2 normal equations. False for parallel segments or
// an answer beyond an end of either (the samples, which every segment's ends are, take the contact there). An answer
// at an end counts: a corner resting on the other body's edge has that edge against its faces, which only the edge
// pair holds.
bool crossing(const Eigen::Vector3d& p, const Eigen::Vector3d& d, const Eigen::Vector3d& q, const Eigen::Vector3d& e,
              double& s, double& t) {
  const double dd = d.squaredNorm(), ee = e.squaredNorm(), de = d.dot(e);
  const Eigen::Vector3d r = p - q;
  const double denominator = dd * ee - de * de;
  // Within a milliradian of parallel the normal across them is lost to rounding; the ends (samples) hold them.
  if (!(denominator > 1e-6 * dd * ee)) return false;
  s = (de * e.dot(r) - ee * d.dot(r)) / denominator;
  t = (dd * e.dot(r) - de * d.dot(r)) / denominator;
  constexpr double kEnd = 1e-9;  // of the segment's length: rounding at an end
  if (!(s >= -kEnd && s <= 1.0 + kEnd && t >= -kEnd && t <= 1.0 + kEnd)) return false;
  s = std::clamp(s, 0.0, 1.0);
  t = std::clamp(t, 0.0, 1.0);
  return true;
}

// The distance between the segments p + s·d and q + t·e (0 ≤ s, t ≤ 1): the closest point of one segment to the
// other's clamped, then the other's to it.
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& d, const Eigen::Vector3d& q,
                        const Eigen::Vector3d& e) {
  const double dd = d.squaredNorm(), ee = e.squaredNorm(), de = d.dot(e);
  const Eigen::Vector3d r = p - q;
  const double denominator = dd * ee - de * de;
  double s = denominator > 1e-12 * dd * ee ? std::clamp((de * e.dot(r) - ee * d.dot(r)) / denominator, 0.0, 1.0) : 0.0;
  const double t = ee > 0.0 ? std::clamp((e.dot(r) + s * de) / ee, 0.0, 1.0) : 0.0;
  s = dd > 0.0 ? std::clamp((t * de - d.dot(r)) / dd, 0.0, 1.0) : 0.0;
  return (p + s * d - q - t * e).norm();
}

// Whether `direction` lies in a sharp edge's normal cone (between its faces' outward normals, world frame); any
// direction does for a round edge.
bool in_cone(const Eigen::Vector3d& direction, const Eigen::Vector3d& face_a, const Eigen::Vector3d& face_b) {
  // An edge pushes along its faces' own normals too, and a milliradian beyond them: an edge lying on the other's face
  // (a capsule along a box's top, over its rim) tilts the normal across the face's normal, back and forth between one
  // pass and the next, and a cone without room drops and takes the pair back each time. A plane tilted by 1 mrad at
  // the edge cuts 1 µm into the room above the face 1 mm away from it.
  constexpr double kSlack = 1e-3;
  return direction.dot(face_a) >= -kSlack && direction.dot(face_b) >= -kSlack;
}

// The largest distance from a body's centre that its samples (balls) reach: its bounding radius, since every kind's
// samples hold its farthest points (a box's corners, a capsule's ends, a cylinder's rims, a ball's centre).
double radius_of(const ContactSamples& samples, int count) {
  double radius_m = 0.0;
  for (int k = 0; k < count; ++k) {
    const ContactSample& sample = samples[static_cast<std::size_t>(k)];
    radius_m = std::max(radius_m, sample.point_m.norm() + sample.radius_m);
  }
  return radius_m;
}

// Distance from `point` to the segment from `a` to `b`.
double distance_to_segment(const Eigen::Vector3d& point, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((point - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (point - a - t * ab).norm();
}

}  // namespace

namespace tool_detail {

// A body's edge placed in the world: from from_m along along_m, and the ball about its middle that holds it.
struct PlacedEdge {
  const ContactEdge* edge;
  int index;
  Eigen::Vector3d from_m;
  Eigen::Vector3d along_m;
  Eigen::Vector3d middle_m;
  double half_reach_m;  // half its length plus its radius
};

// A body placed in the world, as the contacts see it: its shape, centre, turn (body → world), bounding radius,
// samples and edges.
struct PlacedBody {
  const Shape* shape;
  Eigen::Vector3d centre_m;
  Eigen::Matrix3d rotation;
  double radius_m;
  const ContactSamples* samples;
  int sample_count;
  const ContactEdges* edges;
  int edge_count;

  Eigen::Vector3d point(const Eigen::Vector3d& body_m) const { return centre_m + rotation * body_m; }
  Eigen::Vector3d local(const Eigen::Vector3d& world_m) const { return rotation.transpose() * (world_m - centre_m); }
  // The body's surface point nearest a world point (common/shape/shape.h), in world terms. A mesh's normal at an edge
  // or a corner is its pseudo-normal, which tells inside from outside; outside, the way from the surface to the point
  // is the direction the two are apart, which is a primitive's normal there.
  SurfacePoint nearest(const Eigen::Vector3d& world_m) const {
    const Eigen::Vector3d here_m = rotation.transpose() * (world_m - centre_m);
    SurfacePoint body = nearest_surface_point_body(*shape, here_m);
    if (shape->kind == ShapeKind::mesh && body.signed_distance_m > kOnSurface_m) {
      body.normal = (here_m - body.point_m).normalized();
    }
    return {point(body.point_m), rotation * body.normal, body.signed_distance_m};
  }
  // The edges that pass within `within_m` of a ball of `radius_m` about `centre_m`, placed in the world; the least
  // amount by which another missed `within_m` lowers `missed_m`.
  int edges_near(const Eigen::Vector3d& centre_m, double radius_m, double within_m,
                 std::array<PlacedEdge, kMaxContactEdges>& near, double& missed_m) const {
    const Eigen::Vector3d here_m = local(centre_m);  // in the body's frame, where its edges are given
    int count = 0;
    for (int k = 0; k < edge_count; ++k) {
      const ContactEdge& edge = (*edges)[static_cast<std::size_t>(k)];
      const double beyond_m = distance_to_segment(here_m, edge.from_m, edge.to_m) - edge.radius_m - radius_m - within_m;
      if (beyond_m > 0.0) {
        missed_m = std::min(missed_m, beyond_m);
        continue;
      }
      near[static_cast<std::size_t>(count++)] = placed_edge(k);
    }
    return count;
  }
  PlacedEdge placed_edge(int k) const {
    const ContactEdge& edge = (*edges)[static_cast<std::size_t>(k)];
    const Eigen::Vector3d from_m = point(edge.from_m), along_m = rotation * (edge.to_m - edge.from_m);
    return {&edge, k, from_m, along_m, from_m + 0.5 * along_m, 0.5 * along_m.norm() + edge.radius_m};
  }
};

}  // namespace tool_detail

namespace {

using tool_detail::PlacedBody;
using tool_detail::PlacedEdge;
using Kind = ToolConstraint::Kind;

// A contact's point on the object is its point on the tool moved back by the gap along the normal: the two differ
// only along the normal, so the torque the world receives and the torque the hand feels cancel to rounding (the
// nearest points already do; a crossing clamped onto an edge's end is put in line).
ToolConstraint in_line(ToolConstraint constraint) {
  constraint.object_point_m = constraint.tool_point_m - constraint.gap_m * constraint.normal;
  return constraint;
}

// The tool's sample k against a plane taken as the half-space it is.
ToolConstraint tool_sample_on_plane(std::int32_t index, const ContactPlane& plane, const PlacedBody& tool, int k) {
  const ContactSample& sample = (*tool.samples)[static_cast<std::size_t>(k)];
  const Eigen::Vector3d p_m = tool.point(sample.point_m);
  const double distance_m = plane.normal.dot(p_m - plane.point_m);
  return in_line({index,
          plane.object_id,
          plane.normal,
          p_m - sample.radius_m * plane.normal,
          p_m - distance_m * plane.normal,
          distance_m - sample.radius_m,
          Kind::tool_sample,
          static_cast<std::int16_t>(k),
          -1});
}

// The tool's sample k against the object's surface: the tangent plane at the point nearest it.
ToolConstraint tool_sample_on_body(std::int32_t index, const ContactPlane& plane, const PlacedBody& tool,
                                   const PlacedBody& object, int k) {
  const ContactSample& sample = (*tool.samples)[static_cast<std::size_t>(k)];
  const Eigen::Vector3d p_m = tool.point(sample.point_m);
  const SurfacePoint surface = object.nearest(p_m);
  return in_line({index,
          plane.object_id,
          surface.normal,
          p_m - sample.radius_m * surface.normal,
          surface.point_m,
          surface.signed_distance_m - sample.radius_m,
          Kind::tool_sample,
          static_cast<std::int16_t>(k),
          -1});
}

// The object's sample k against the tool's surface: the tool's tangent plane at its point nearest the sample.
ToolConstraint object_sample_on_tool(std::int32_t index, const ContactPlane& plane, const PlacedBody& tool,
                                     const PlacedBody& object, int k) {
  const ContactSample& sample = (*object.samples)[static_cast<std::size_t>(k)];
  const Eigen::Vector3d v_m = object.point(sample.point_m);
  const SurfacePoint surface = tool.nearest(v_m);
  return in_line({index,
          plane.object_id,
          -surface.normal,
          surface.point_m,
          v_m - sample.radius_m * surface.normal,
          surface.signed_distance_m - sample.radius_m,
          Kind::object_sample,
          -1,
          static_cast<std::int16_t>(k)});
}

// The tool's edge i against the object's edge j, where they cross (closest points inside both) within `within_m` of
// each other: across both edges, out of the object. The normal lies in the object's edge's cone (toward the tool for a
// round edge) and its opposite in the tool's; false for a pair that does not cross, crosses farther apart, or has no
// such normal (not an edge contact). The closest points of two lines are apart along that normal, so |gap| is their
// distance: the bound keeps a pair whose lines cross far behind each other (a peg's edge in a hole and the hole's
// outer rim) from being taken for an edge the tool is deep into.
bool edge_pair(std::int32_t index, const ContactPlane& plane, const PlacedBody& tool, const PlacedEdge& tool_placed,
               const PlacedBody& object, const PlacedEdge& object_placed, double within_m, ToolConstraint& out) {
  const ContactEdge& tool_edge = *tool_placed.edge;
  const ContactEdge& object_edge = *object_placed.edge;
  const Eigen::Vector3d& p_m = tool_placed.from_m;
  const Eigen::Vector3d& d_m = tool_placed.along_m;
  const Eigen::Vector3d& q_m = object_placed.from_m;
  const Eigen::Vector3d& e_m = object_placed.along_m;
  double s = 0.0, t = 0.0;
  if (!crossing(p_m, d_m, q_m, e_m, s, t)) return false;
  const Eigen::Vector3d on_tool_m = p_m + s * d_m, on_object_m = q_m + t * e_m;
  if ((on_tool_m - on_object_m).norm() - tool_edge.radius_m - object_edge.radius_m > within_m) return false;
  Eigen::Vector3d normal = d_m.cross(e_m).normalized();
  const bool round_object = object_edge.face_a.isZero(0.0);
  const Eigen::Vector3d object_a = object.rotation * object_edge.face_a;
  const Eigen::Vector3d object_b = object.rotation * object_edge.face_b;
  if (round_object ? normal.dot(on_tool_m - on_object_m) < 0.0 : !in_cone(normal, object_a, object_b)) {
    normal = -normal;
  }
  if (!round_object && !in_cone(normal, object_a, object_b)) return false;
  if (!tool_edge.face_a.isZero(0.0) &&
      !in_cone(-normal, tool.rotation * tool_edge.face_a, tool.rotation * tool_edge.face_b)) {
    return false;
  }
  const double gap_m = normal.dot(on_tool_m - on_object_m) - tool_edge.radius_m - object_edge.radius_m;
  // Edges that overlap are in each other's body: a pair whose tool edge (its ball, for a round one) does not reach into
  // the object has the object between the two lines, or beside them, and is no edge contact, whatever its lines do.
  if (gap_m < 0.0 && object.nearest(on_tool_m).signed_distance_m > tool_edge.radius_m + kOnSurface_m) return false;
  out = in_line({index,
                 plane.object_id,
                 normal,
                 on_tool_m - tool_edge.radius_m * normal,
                 on_object_m + object_edge.radius_m * normal,
                 gap_m,
                 Kind::edges,
                 static_cast<std::int16_t>(tool_placed.index),
                 static_cast<std::int16_t>(object_placed.index)});
  return true;
}

// Every pair of the tool's and the object's edges near each other (`within_m`: how far apart, or how deep, a contact
// may be and still act) that cross as an edge contact (edge_pair): visit(the constraint); with `open_pairs`, also
// those within reach that do not cross yet, as open constraints (gap kOpenGap_m). The least amount by which a pair
// left out missed `within_m` lowers `missed_m`.
template <typename Visit>
void visit_crossings(std::int32_t index, const ContactPlane& plane, const PlacedBody& tool, const PlacedBody& object,
                     double within_m, bool open_pairs, double& missed_m, Visit&& visit) {
  std::array<PlacedEdge, kMaxContactEdges> tool_near, object_near;
  const int tool_count = tool.edges_near(object.centre_m, object.radius_m, within_m, tool_near, missed_m);
  if (tool_count == 0) return;
  const int object_count = object.edges_near(tool.centre_m, tool.radius_m, within_m, object_near, missed_m);
  for (int a = 0; a < tool_count; ++a) {
    const PlacedEdge& tool_edge = tool_near[static_cast<std::size_t>(a)];
    for (int b = 0; b < object_count; ++b) {
      const PlacedEdge& object_edge = object_near[static_cast<std::size_t>(b)];
      // Two edges are no nearer than their middles' distance less the balls about them that hold them.
      const double apart_m =
          (tool_edge.middle_m - object_edge.middle_m).norm() - tool_edge.half_reach_m - object_edge.half_reach_m;
      if (apart_m > within_m) {
        missed_m = std::min(missed_m, apart_m - within_m);
        continue;
      }
      ToolConstraint constraint;
      if (edge_pair(index, plane, tool, tool_edge, object, object_edge, within_m, constraint)) {
        visit(constraint);
      } else if (open_pairs) {
        // Not crossing here, but within reach: a move may bring their crossing onto both (a corner sliding onto the
        // other's edge). Listed open, for a later pass to measure again.
        const double distance_m =
            segment_distance(tool_edge.from_m, tool_edge.along_m, object_edge.from_m, object_edge.along_m) -
            tool_edge.edge->radius_m - object_edge.edge->radius_m;
        if (distance_m > within_m) {
          missed_m = std::min(missed_m, distance_m - within_m);
          continue;
        }
        constraint = {index, plane.object_id, Eigen::Vector3d::UnitZ(), tool_edge.from_m, object_edge.from_m,
                      kOpenGap_m, Kind::edges, static_cast<std::int16_t>(tool_edge.index),
                      static_cast<std::int16_t>(object_edge.index)};
        visit(constraint);
      }
    }
  }
}

}  // namespace

Eigen::Vector3d object_centre(const ContactPlane& plane) {
  return plane.shape_traits().round ? Eigen::Vector3d(plane.point_m - plane.shape.radius_m * plane.normal)
                                    : plane.com_m;
}

BodyPose object_pose(const ContactPlane& plane) {
  if (plane.shape_traits().round) return {object_centre(plane), Eigen::Quaterniond::Identity()};
  return {plane.com_m, Eigen::Quaterniond(plane.axes).normalized()};
}

ToolContacts::ToolContacts(const ToolShape& tool) : tool_(tool) {
  if (const char* problem = shape_problem(tool.shape)) {
    throw std::invalid_argument(std::string("tool shape: ") + problem);
  }
  sample_count_ = contact_samples(tool.shape, samples_);
  edge_count_ = contact_edges(tool.shape, edges_);
  if (sample_count_ == 0) {
    throw std::invalid_argument(std::string("tool shape: this ") + to_string(tool.shape.kind) +
                                " has no corners and edges to touch by (a tool's mesh must be convex, with at most " +
                                std::to_string(kMaxContactSamples) + " corners and " +
                                std::to_string(kMaxContactEdges) + " sharp edges, and loaded in this process)");
  }
  shape_radius_m_ = radius_of(samples_, sample_count_);
  bounding_radius_m_ = tool.placement.position_m.norm() + shape_radius_m_;
}

const ToolContacts::CachedSamples& ToolContacts::object_features(const ContactPlane& plane) {
  for (int k = 0; k < cached_; ++k) {
    const CachedSamples& cached = cache_[static_cast<std::size_t>(k)];
    if (cached.object_id == plane.object_id && same_shape(cached.shape, plane.shape)) return cached;
  }
  // A new object: the next free slot, or once all are in use the one after the last filled (round robin).
  const int slot =
      cached_ < static_cast<int>(cache_.size()) ? cached_++ : static_cast<int>(cache_turns_++ % cache_.size());
  CachedSamples& cached = cache_[static_cast<std::size_t>(slot)];
  cached.object_id = plane.object_id;
  cached.shape = plane.shape;
  cached.count = contact_samples(plane.shape, cached.samples);
  cached.edge_count = contact_edges(plane.shape, cached.edges);
  cached.radius_m = radius_of(cached.samples, cached.count);
  return cached;
}

void ToolContacts::add(const ToolConstraint& constraint, double lever_m, const ToolReach& reach) {
  const double slack_m = constraint.gap_m - reach.at(lever_m);
  if (count_ < kMaxToolConstraints) {
    slack_m_[static_cast<std::size_t>(count_)] = slack_m;
    constraints_[static_cast<std::size_t>(count_++)] = constraint;
    return;
  }
  // Full: the new constraint replaces the one that has the most room before it could act, if that is more than its.
  ++overflow_;
  int loosest = 0;
  for (int k = 1; k < count_; ++k) {
    if (slack_m_[static_cast<std::size_t>(k)] > slack_m_[static_cast<std::size_t>(loosest)]) loosest = k;
  }
  if (slack_m < slack_m_[static_cast<std::size_t>(loosest)]) {
    slack_m_[static_cast<std::size_t>(loosest)] = slack_m;
    constraints_[static_cast<std::size_t>(loosest)] = constraint;
  }
}

BodyPose ToolContacts::tool_pose(const BodyPose& grip) const {
  return {grip.position_m + grip.orientation * tool_.placement.position_m,
          (grip.orientation * tool_.placement.orientation).normalized()};
}

PlacedBody ToolContacts::placed_tool(const BodyPose& pose) const {
  return {&tool_.shape, pose.position_m, pose.orientation.toRotationMatrix(), shape_radius_m_, &samples_,
          sample_count_, &edges_, edge_count_};
}

PlacedBody ToolContacts::placed_object(const ContactPlane& plane, const CachedSamples& object) {
  return {&plane.shape, object_centre(plane),
          plane.shape_traits().round ? Eigen::Matrix3d::Identity() : plane.axes, object.radius_m, &object.samples,
          object.count, &object.edges, object.edge_count};
}

bool ToolContacts::path_clear(const PlaneSet& planes, const BodyPose& from, const BodyPose& to) {
  const BodyPose start = tool_pose(from), end = tool_pose(to);
  const PlacedBody start_tool = placed_tool(start);
  const PlacedBody end_tool = placed_tool(end);
  // How far any point of the tool moved: its centre's way and its turn at its radius.
  const double travel_m = (end.position_m - start.position_m).norm() +
                          turn_between(start.orientation, end.orientation).norm() * shape_radius_m_;
  for (std::uint32_t j = 0; j < planes.count; ++j) {
    const ContactPlane& plane = planes.planes[j];
    if (!plane.shaped() || !plane.shape_traits().convex) {
      // A half-space is entered only by ending behind it (where it describes its object).
      if (plane.normal.dot(end.position_m - plane.point_m) >= shape_radius_m_) continue;
      const double extent_m = plane.describes_within_m();
      for (int k = 0; k < sample_count_; ++k) {
        const ContactSample& sample = samples_[static_cast<std::size_t>(k)];
        const Eigen::Vector3d p_m = end_tool.point(sample.point_m);
        const double distance_m = plane.normal.dot(p_m - plane.point_m);
        if (distance_m >= sample.radius_m) continue;
        if (extent_m > 0.0 && (p_m - distance_m * plane.normal - plane.point_m).norm() > extent_m) continue;
        return false;
      }
      continue;
    }
    // Every point of the tool on its way lies within its radius of its centre's straight way (the samples' ways are
    // straight between two placements): an object farther from that than both radii is not met.
    const CachedSamples& object = object_features(plane);
    const PlacedBody placed = placed_object(plane, object);
    if (distance_to_segment(placed.centre_m, start.position_m, end.position_m) > shape_radius_m_ + object.radius_m) {
      continue;
    }
    for (int k = 0; k < sample_count_; ++k) {
      const ContactSample& sample = samples_[static_cast<std::size_t>(k)];
      const Eigen::Vector3d from_m = start_tool.point(sample.point_m), to_m = end_tool.point(sample.point_m);
      if (distance_to_segment(placed.centre_m, from_m, to_m) > object.radius_m + sample.radius_m) continue;
      if (segment_enters(plane, from_m, to_m, -sample.radius_m)) return false;
    }
    for (int k = 0; k < object.count; ++k) {
      const ContactSample& sample = object.samples[static_cast<std::size_t>(k)];
      const Eigen::Vector3d v_m = placed.point(sample.point_m);
      const Eigen::Vector3d from_m = start_tool.rotation.transpose() * (v_m - start.position_m);
      const Eigen::Vector3d to_m = end_tool.rotation.transpose() * (v_m - end.position_m);
      if (distance_to_segment(Eigen::Vector3d::Zero(), from_m, to_m) > shape_radius_m_ + sample.radius_m) continue;
      if (segment_enters_body(tool_.shape, from_m, to_m, -sample.radius_m)) return false;
    }
    // Crossing edges that overlap where the way ends, no deeper than the tool travelled (it started clear).
    bool overlap = false;
    double missed_m = 0.0;  // not needed here
    visit_crossings(static_cast<std::int32_t>(j), plane, end_tool, placed, travel_m, false, missed_m,
                    [&](const ToolConstraint& constraint) { overlap = overlap || constraint.gap_m < 0.0; });
    if (overlap) return false;
  }
  return true;
}

int ToolContacts::gather(const PlaneSet& planes, const BodyPose& grip, const ToolReach& reach) {
  count_ = 0;
  missed_m_ = std::numeric_limits<double>::infinity();
  const std::uint64_t overflow_before = overflow_;
  const BodyPose pose_now = tool_pose(grip);
  const PlacedBody tool = placed_tool(pose_now);
  // How far any point of the tool can travel in this solve: from the lever of its farthest point.
  const double tool_reach_m = reach.at((pose_now.position_m - grip.position_m).norm() + shape_radius_m_);
  // Each test below leaves a feature out when a bound on its gap exceeds the reach; by how much, the least of them.
  const auto within = [&](double gap_bound_m, double reach_m) {
    if (gap_bound_m <= reach_m) return true;
    missed_m_ = std::min(missed_m_, gap_bound_m - reach_m);
    return false;
  };
  const auto add_within = [&](const ToolConstraint& constraint) {
    const double lever_m = (constraint.tool_point_m - grip.position_m).norm();
    if (within(constraint.gap_m, reach.at(lever_m))) add(constraint, lever_m, reach);
  };
  for (std::uint32_t j = 0; j < planes.count; ++j) {
    const ContactPlane& plane = planes.planes[j];
    const auto index = static_cast<std::int32_t>(j);
    if (!plane.shaped() || !plane.shape_traits().convex) {
      // A half-space as sent: the tool's samples stay in front of it, within the part of it that describes its
      // object (a mesh's plane, extent_m), or all of it (the floor).
      if (!within(plane.normal.dot(pose_now.position_m - plane.point_m) - shape_radius_m_, tool_reach_m)) continue;
      const double extent_m = plane.describes_within_m();
      for (int k = 0; k < sample_count_; ++k) {
        const ToolConstraint constraint = tool_sample_on_plane(index, plane, tool, k);
        if (extent_m > 0.0 && (constraint.object_point_m - plane.point_m).norm() > extent_m) continue;
        add_within(constraint);
      }
      continue;
    }
    const CachedSamples& object = object_features(plane);
    const PlacedBody placed = placed_object(plane, object);
    if (!within((placed.centre_m - pose_now.position_m).norm() - shape_radius_m_ - object.radius_m, tool_reach_m)) {
      continue;
    }

    // The tool's samples against the object's surface; first whether the object's bounding ball is in reach, in the
    // tool's own frame (no sample moved into the world for that).
    const Eigen::Vector3d object_in_tool_m = tool.local(placed.centre_m);
    for (int k = 0; k < sample_count_; ++k) {
      const ContactSample& sample = samples_[static_cast<std::size_t>(k)];
      if (!within((sample.point_m - object_in_tool_m).norm() - sample.radius_m - object.radius_m, tool_reach_m)) {
        continue;
      }
      add_within(tool_sample_on_body(index, plane, tool, placed, k));
    }
    // The object's samples against the tool's surface, the same way round.
    const Eigen::Vector3d tool_in_object_m = placed.local(pose_now.position_m);
    for (int k = 0; k < object.count; ++k) {
      const ContactSample& sample = object.samples[static_cast<std::size_t>(k)];
      if (!within((sample.point_m - tool_in_object_m).norm() - sample.radius_m - shape_radius_m_, tool_reach_m)) {
        continue;
      }
      add_within(object_sample_on_tool(index, plane, tool, placed, k));
    }
    // The edges that cross.
    visit_crossings(index, plane, tool, placed, tool_reach_m, true, missed_m_, [&](const ToolConstraint& constraint) {
      if (constraint.gap_m == kOpenGap_m) {
        add(constraint, (constraint.tool_point_m - grip.position_m).norm(), reach);
      } else {
        add_within(constraint);
      }
    });
  }
  // A list that had to drop constraints depends on the reach through their ranking: not complete for a larger one.
  if (overflow_ != overflow_before) missed_m_ = 0.0;
  return count_;
}

void ToolContacts::refresh(const PlaneSet& planes, const BodyPose& grip, const ToolReach& reach) {
  const BodyPose pose_now = tool_pose(grip);
  const PlacedBody tool = placed_tool(pose_now);
  // Gathered object by object: each object is placed once for its run of constraints.
  PlacedBody placed{};
  std::int32_t placed_plane = -1;
  for (int k = 0; k < count_; ++k) {
    ToolConstraint& c = constraints_[static_cast<std::size_t>(k)];
    const ContactPlane& plane = planes.planes[static_cast<std::size_t>(c.plane)];
    if (!plane.shaped() || !plane.shape_traits().convex) {
      c = tool_sample_on_plane(c.plane, plane, tool, c.tool_feature);
      continue;
    }
    if (c.plane != placed_plane) {
      placed = placed_object(plane, object_features(plane));
      placed_plane = c.plane;
    }
    switch (c.kind) {
      case Kind::tool_sample: c = tool_sample_on_body(c.plane, plane, tool, placed, c.tool_feature); break;
      case Kind::object_sample: c = object_sample_on_tool(c.plane, plane, tool, placed, c.object_feature); break;
      case Kind::edges:
        if (!edge_pair(c.plane, plane, tool, tool.placed_edge(c.tool_feature), placed,
                       placed.placed_edge(c.object_feature), reach.at((c.tool_point_m - grip.position_m).norm()), c)) {
          c.gap_m = kOpenGap_m;
        }
        break;
    }
  }
}

}  // namespace impetus
