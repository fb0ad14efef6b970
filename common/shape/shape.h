// SPDX-License-Identifier: Apache-2.0
#pragma once
// The shapes a scene's bodies have, in one place for both processes, the viewer and Python (docs/architecture.md §7).
//
// A `Shape` is a tagged descriptor: its kind and the dimensions that kind reads. It is plain data of fixed size, so
// the same value is parsed from a scene, carried by every plane on the world link and shown to viewers. What a kind
// means lives in its own file (box.cpp, sphere.cpp, …: its JSON keys and their validation,
// closest point and outward normal, support function, segment test, bounds, volume and inertia, and how the haptic
// side takes its plane again under a moving proxy); this header dispatches through one table (shape.cpp), after
// Box2D's shape functions and MuJoCo's collision table. Adding a kind: its file, its entry in that table, a line in
// each engine adapter (world_manager/engine/) and a geometry in the viewer page (viewer/web/viewer.js).
//
// Frames: a shape is centred on its body's origin, which is the body's centre of mass; a kind with an axis of
// symmetry has it along body z. Units SI. Every function here is allocation-free and never throws, except the JSON
// parser, which runs before anything starts.

#include "common/contract/vec3.h"
#include "common/shape/shape_descriptor.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace impetus {

class JsonNode;

// A point this close to a surface is on it: the god-object puts a proxy that slides up to an edge on it only to
// rounding (~1e-17 m), and a point on the surface has no direction to take a normal from. Retaking a plane treats a
// proxy within it of a rim as on the rim, and a way from the proxy enters a body only past it.
inline constexpr double kOnSurface_m = 1e-9;

// What the code outside a kind's file may know about it, instead of its name.
struct ShapeTraits {
  // Its planes carry the body's axes, so the haptic side can retake them from the shape (a sphere needs none: its
  // plane carries the centre as point − radius·normal).
  bool carries_axes = false;
  // Its surface is flat faces meeting at edges (a box): a face's plane turns rigidly with the body, and inside the
  // body any face other than the one the finger met is one the body brought over it.
  bool flat_faces = false;
  // A ball: its surface is the same under any spin (remembered in world axes; it rolls on its supports), and its
  // plane's point − radius·normal is its centre.
  bool round = false;
  // A push along a plane's normal passes through the core under its point (point − radius·normal) and turns the body
  // only if that core point lies off the centre of mass (a ball; a long body with a round cross-section and ends).
  bool normal_through_core = false;
  // Convex: its supporting planes (support_m) touch its surface, so the world may keep the face a finger went in by
  // and take its plane again from the support function (a primitive; not a mesh, which may be concave).
  bool convex = false;
};

// Pose of a body: world = orientation · body + position.
struct BodyPose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // unit
};

struct SurfacePoint {
  Eigen::Vector3d point_m;  // on the surface
  Eigen::Vector3d normal;   // unit, outward
  // Distance from the query point to the surface: positive outside, negative inside (−penetration depth).
  double signed_distance_m = 0.0;
};

// A plane of a placed shape as the haptic side carries it between world frames (paper §3.1–3.2): the plane, and the
// shape it belongs to with the body's centre and axes. For a ball (traits().round) the centre is
// point − radius·normal and the axes are not used.
struct ShapePlane {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, out of the body
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: body x, y, z in the world frame
  Shape shape;
};

// --- Names, keys and validation -----------------------------------------------------------------------------------

const char* to_string(ShapeKind kind);  // "box", …; "none"
// The kind named `name` in a scene; false for an unknown name (or "none").
bool shape_kind_from_string(std::string_view name, ShapeKind& kind);
// The scene names of every kind, as "a, b or c": for error messages.
std::string shape_kind_names();
const ShapeTraits& traits(ShapeKind kind);

// The JSON keys of a kind's own dimensions in a scene object ("size_m"; "radius_m", "length_m").
std::span<const std::string_view> shape_keys(ShapeKind kind);
// A "shape" value: a kind's name, else an error naming the known ones.
ShapeKind parse_shape_kind(const JsonNode& node);
// Reads a kind's dimensions from a scene object, each checked against the scene's length limits; throws InputError
// naming the key and the value.
Shape parse_shape(const JsonNode& object, ShapeKind kind);
// Why a received descriptor cannot be used (not finite, a dimension out of its kind's range, an unknown kind), or
// nullptr. Links check every shape they decode with it.
const char* shape_problem(const Shape& shape);

// --- Geometry in the body frame -----------------------------------------------------------------------------------

// Nearest surface point to `query_m`. Inside the shape this is the nearest face, not the far side, and the normal still
// points outward there, so a penetrating finger is pushed out the short way. Where the nearest point is not unique (a
// sphere's centre, a round body's axis) a fixed direction is chosen (+z for a sphere, +x radially) so the
// answer is deterministic.
SurfacePoint nearest_surface_point_body(const Shape& shape, const Eigen::Vector3d& query_m);
// The support function h(n) = max over the shape of n·x, for a unit `normal_body`.
double support_m(const Shape& shape, const Eigen::Vector3d& normal_body);
// Whether the segment from `from_m` to `to_m` passes through the shape shrunk by `margin_m` (its interior for 0): a
// segment that starts on the surface and leaves does not enter.
bool segment_enters_body(const Shape& shape, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                         double margin_m = 0.0);
// Faces of a flat-faced shape whose planes the point `q` (inside, on, or within `tolerance_m` outside) is nearest to,
// within `tolerance_m` of the nearest: their outward unit normals, lowest axis first. Returns the count (one in a
// face's interior, two on an edge, three at a corner; 0 farther outside, or for a shape without flat faces).
int nearest_faces_body(const Shape& shape, const Eigen::Vector3d& q, double tolerance_m,
                       std::array<Eigen::Vector3d, 3>& normals);

double volume_m3(const Shape& shape);
// Inertia about the centre of mass in the body frame of a solid of uniform density and `mass_kg` (kg·m²).
Eigen::Matrix3d inertia_kgm2(const Shape& shape, double mass_kg);

// How far from its point a plane of the shape still describes it (Plane::extent_m): the radius of a round shape (a
// tangent plane one radius from its point is beside the body, no longer on it), a box's space diagonal (no two of its
// points are farther apart).
double plane_extent_m(const Shape& shape);
// How far from a plane's point a finger may lie and still be in or on the body (the god-object's test of a plane
// whose body is beside the finger): plane_extent_m, or for a long body the diagonal of the cylinder that bounds it.
double describes_within_m(const Shape& shape);

// --- Placed in the world ------------------------------------------------------------------------------------------

SurfacePoint nearest_surface_point(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m);
// The shape's supporting plane with outward unit normal `normal_body` (body frame), taken at the query: the plane
// {x : n·x = h(n)}; the result's point is the query projected onto it (for a round shape the support point r·n, so
// that point − r·normal stays the centre), its normal n in the world, its signed distance n·query − h(n). For a box
// and a face normal this is that face's plane.
SurfacePoint supporting_plane(const Shape& shape, const BodyPose& pose, const Eigen::Vector3d& query_m,
                              const Eigen::Vector3d& normal_body);
// Tight world-frame axis-aligned bounding box of the shape at `pose`.
Eigen::AlignedBox3d world_bounds(const Shape& shape, const BodyPose& pose);
// The largest extent of the shape's axis-aligned box in its own frame (m): a size scale for broadphase cells.
double largest_extent_m(const Shape& shape);

// --- Planes on the haptic side ------------------------------------------------------------------------------------

// Takes the plane again from its shape about `around_m` (the proxy), the rules of each kind's file: a sphere's or a
// round body's tangent plane at the point nearest `around_m`; a box face's plane while `around_m` stays over that face,
// its nearest edge, corner or neighbouring face once past the rim; a cylinder's side under the proxy, a cap's to its
// rim. A plane without a shape is left as it is.
void retake_plane(ShapePlane& plane, const Eigen::Vector3d& around_m);
// Whether the segment between two world points passes through the plane's body shrunk by `margin_m`.
bool segment_enters(const ShapePlane& plane, const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                    double margin_m);
// The corners of the face of a flat-faced body that looks along −n (its support's side), relative to the centre of
// mass, world frame, for body axes `axes`: the four points a support touches it at. Returns the count (0 for a shape
// without flat faces).
int support_corners(const Shape& shape, const Eigen::Matrix3d& axes, const Eigen::Vector3d& n,
                    std::array<Eigen::Vector3d, 4>& corners);

// --- Contact features (a rigid tool's contacts, docs/tool.md) ---------------------------------------------------

// Where two convex bodies touch, a corner of one meets the other's surface, or an edge of each crosses the other
// (the features of polyhedral contact, as the separating-axis test names them); a round part touches as its core
// swept by its radius. So a shape's contacts are stood for by its samples (balls: its corners, or the cores of its
// round parts), each tested against the other body's exact surface, and its edges (segments swept by balls), each
// tested against the other body's edges where they cross.
struct ContactSample {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // body frame, within the shape
  double radius_m = 0.0;
};
inline constexpr int kMaxContactSamples = 32;
using ContactSamples = std::array<ContactSample, kMaxContactSamples>;
// The kind's samples: a box's eight corners; a ball's centre and a capsule's two cap centres (radius r); a
// cylinder's two rims, 16 points each (a chord of 22.5° lies within r·(1 − cos 11.25°) = 0.019·r of the rim); a
// convex mesh's corners, if it has at most kMaxContactSamples (mesh_geometry.h). Returns the count (0: none stand for
// the shape — any other mesh, or one this process has not loaded).
int contact_samples(const Shape& shape, ContactSamples& samples);

struct ContactEdge {
  Eigen::Vector3d from_m = Eigen::Vector3d::Zero();  // body frame
  Eigen::Vector3d to_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  // A sharp edge's two faces' outward normals (body frame): the directions the edge can push along lie between them
  // (its normal cone). Zero for a round edge, which pushes along any direction across it.
  Eigen::Vector3d face_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d face_b = Eigen::Vector3d::Zero();
};
inline constexpr int kMaxContactEdges = 33;
using ContactEdges = std::array<ContactEdge, kMaxContactEdges>;
// The kind's edges: a box's twelve (radius 0, with their faces); the axis of a capsule or a cylinder, cap centre to
// cap centre, swept by r (a cylinder's side), and a cylinder's rims as 16 chords each (with the cap's and the
// side's normals as their faces; its flat caps are met by the other body's samples); a convex mesh's sharp edges,
// with the samples above. None for a ball. Returns the count.
int contact_edges(const Shape& shape, ContactEdges& edges);

}  // namespace impetus
