// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scripted finger trajectories: where the simulated hand wants the fingertip to be at each time
// (docs/trajectory-format.md). World frame, metres, seconds; time 0 is the start of the device session.
//
// A trajectory is either a CSV file or a built-in with named parameters. Evaluation (`position_at`, `velocity_at`) is
// allocation-free and safe to call from the device tick; loading allocates and throws `TrajectoryError`.
//
// CSV files
//   The first line is exactly the header `t,x,y,z` (s, m, m, m), or `t,x,y,z,qw,qx,qy,qz` for a hand that also turns
//   what it holds (the grip SPIDAR's): its orientation, grip → world, as a unit quaternion (to 10⁻³; it is
//   normalised). Each following line is one waypoint; time must be non-negative and strictly increasing, every value
//   finite. Blank lines are skipped. Between waypoints the position is interpolated linearly and the orientation
//   along the shorter great arc (slerp: a turn at constant angular velocity); before the first waypoint the first is
//   held, after the last the last is held. Without orientation columns the orientation is the identity.
//   Errors read `FILE:LINE:COLUMN (column name): reason (got 'text')`, LINE and COLUMN 1-based, COLUMN counting
//   characters, so an editor can jump to the offending field.
//
// Built-ins: `NAME[:key=value,...]`, e.g. `tap:speed=0.5,depth=0.035,height=0.025`. Every parameter has a default;
// an unknown key, a repeated key, a value that is not a number or is out of range is an error naming the key and the
// value. All motions start and end at rest and have continuous velocity (cosine velocity ramps), so a finger that
// starts at rest on the target can follow them without an initial jolt.
//
//   tap     The paper's task: strike the −x face of a cube along +x, push past it, withdraw, hold.
//           The finger starts at rest at (face_x − standoff, y, height), waits there for `rest`, accelerates over the
//           first half of the
//           standoff to `speed`, meets the face's rest position at `speed`, decelerates to rest `depth` past it
//           (x = face_x + depth; the cube gives way, so the real penetration is much smaller), withdraws back to the
//           start with a smooth (cosine) profile whose peak speed is `speed`, and holds there for `hold`.
//           This is the target; a simulated finger lags it through the hand impedance (with spidar_sim's default hand
//           it still rings from the approach ramp and meets the face ~15 % faster than `speed`).
//             speed    = 0.5    m/s  approach speed at the face                        (> 0)
//             depth    = 0.035  m    how far past the face's rest position to push     (> 0)
//             height   = 0.025  m    z of the strike (middle of a 5 cm cube on the floor)
//             face_x   = 0.005  m    x of the struck face at rest
//             y        = 0      m    y of the strike
//             standoff = 0.03   m    start distance in front of the face               (> 0)
//             hold     = 1.5    s    time held at the start after withdrawing, so the cube can come to rest (>= 0)
//             rest     = 0      s    time at rest at the start before the stroke, e.g. for a delayed world link
//                                    to bring the first frames before the finger moves (>= 0)
//
//   press   Down onto a horizontal surface and hold below it.
//           Starts at rest at (x, y, surface_z + standoff), accelerates over the first half of the standoff to
//           `speed`, meets the surface at `speed`, decelerates to rest at surface_z − depth and holds there for
//           `hold`, after which the trajectory ends (the last point is held).
//             x         = 0      m    x of the press
//             y         = 0      m    y of the press
//             surface_z = 0.05   m    z of the surface (top of a 5 cm cube on the floor)
//             depth     = 0.01   m    how far below the surface to push                 (> 0)
//             standoff  = 0.03   m    start height above the surface                    (> 0)
//             speed     = 0.1    m/s  approach speed at the surface                     (> 0)
//             hold      = 1.0    s    time held at the bottom                           (>= 0)
//
//   slide   A press, then a drag along x at constant depth, then a hold.
//           The press is as above with `settle` instead of `hold`; then the finger drags by `distance` along x
//           (negative: toward −x), accelerating and decelerating over a quarter of the distance each, cruising at
//           `speed` in between, and holds at the end for `hold`.
//             x, y, surface_z, depth, standoff  as for press
//             press_speed = 0.1  m/s  approach speed at the surface                     (> 0)
//             settle    = 0.2    s    time held at depth before dragging                (>= 0)
//             distance  = 0.05   m    signed drag along x                               (!= 0)
//             speed     = 0.05   m/s  drag speed                                        (> 0)
//             hold      = 0.5    s    time held at the end of the drag                  (>= 0)
//
//   circle  `turns` laps of a circle, starting and ending at rest at centre + radius·(first in-plane axis).
//           The first half lap speeds up and the last half lap slows down (cosine velocity ramps); in between one
//           lap takes `period`.
//             radius   = 0.03   m    circle radius                                      (> 0)
//             period   = 1.0    s    time of one lap at full speed                      (> 0)
//             cx, cy, cz = 0, 0, 0.05  m  centre (the default is the device's workspace centre)
//             plane    = xy          xy, xz or yz: the plane of the circle; laps run counter-clockwise seen from
//                                    the positive third axis (x→y, x→z, y→z)
//             turns    = 2           laps, including the half-lap ramps                  (>= 1)

#include "common/contract/vec3.h"

#include <Eigen/Geometry>

#include <istream>
#include <stdexcept>
#include <string>
#include <vector>

namespace impetus {

// A trajectory file or spec that cannot be used; the message says where and why.
class TrajectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// How progress along a segment unfolds in time; τ ∈ [0, 1] is the fraction of the segment's duration elapsed and
// s(τ) ∈ [0, 1] the fraction of its path covered.
enum class Easing {
  linear,       // s = τ: constant speed
  smooth,       // s = (1 − cos πτ)/2: from rest to rest, peak speed π/2 × the mean
  accelerate,   // s = τ − sin(πτ)/π: from rest to 2 × the mean speed (cosine velocity ramp up)
  decelerate,   // s = τ + sin(πτ)/π: from 2 × the mean speed to rest (cosine velocity ramp down)
};

// One piece of a trajectory: a straight line or a circular arc traversed with an easing, over [begin_s, end_s].
struct TrajectorySegment {
  enum class Path { line, arc };
  Path path = Path::line;
  Easing easing = Easing::linear;
  double begin_s = 0.0;
  double end_s = 0.0;
  // Line: from `from_m` to `to_m`.
  Vec3 from_m{};
  Vec3 to_m{};
  // Arc: centre + radius·(cos θ·axis_u + sin θ·axis_v), θ from begin_angle_rad to end_angle_rad. Axes orthonormal.
  Vec3 centre_m{};
  Vec3 axis_u{};
  Vec3 axis_v{};
  double radius_m = 0.0;
  double begin_angle_rad = 0.0;
  double end_angle_rad = 0.0;
};

struct Waypoint {
  double t_s = 0.0;
  Vec3 position_m{};
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // grip → world, unit (for a hand that turns)
};

class Trajectory {
 public:
  // Contiguous segments in time order (each begins where the previous ends, the first at or after 0). Throws
  // TrajectoryError if they are empty, overlap, leave gaps, go backwards in time or hold non-finite values.
  Trajectory(std::vector<TrajectorySegment> segments, std::string description);

  // Linear interpolation through waypoints (at least one; times >= 0 and strictly increasing; finite), and slerp
  // through their orientations if `turning` (else the orientation is the identity throughout).
  static Trajectory from_waypoints(const std::vector<Waypoint>& waypoints, std::string description,
                                   bool turning = false);

  // Target position (m) at session time t_s; holds the first point before the start and the last after the end.
  Vec3 position_at(double t_s) const;
  // Target velocity (m/s), the time derivative of position_at; zero outside the trajectory.
  Vec3 velocity_at(double t_s) const;
  // Both at once, with one segment look-up: exactly {position_at(t_s), velocity_at(t_s)}. `segment_hint` (in/out)
  // is where the previous sample's segment was: a caller whose times mostly increase (a device's sub-steps) finds the
  // segment in O(1) instead of a search. Any value is valid; the sample does not depend on it.
  struct Sample {
    Vec3 position_m;
    Vec3 velocity_mps;
  };
  Sample sample_at(double t_s) const;
  Sample sample_at(double t_s, std::size_t& segment_hint) const;
  // Target orientation (grip → world) at t_s, and its angular velocity (rad/s, world frame), constant between two
  // waypoints; the identity and zero for a trajectory that does not turn. Allocation-free.
  Eigen::Quaterniond orientation_at(double t_s) const;
  Eigen::Vector3d angular_velocity_at(double t_s) const;
  bool turns() const { return !turns_.empty(); }
  // Time (s) of the last point; after it the target holds still.
  double duration_s() const { return segments_.back().end_s; }
  // The same path, then holding its last point until end_s (if later than its own end): the fingers of one device
  // run for as long as the longest of their trajectories.
  Trajectory held_until(double end_s) const;
  // The spec or path this trajectory was made from, for logs and run summaries.
  const std::string& description() const { return description_; }
  const std::vector<TrajectorySegment>& segments() const { return segments_; }

 private:
  // Index of the first segment still running at t_s (t_s < its end), the last if none is; `hint` is tried first.
  std::size_t segment_index_at(double t_s, std::size_t hint) const;

  // A turn between two waypoints: from `from` at begin_s at constant angular velocity (world frame).
  struct Turn {
    double begin_s = 0.0;
    double end_s = 0.0;
    Eigen::Quaterniond from = Eigen::Quaterniond::Identity();
    Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  };
  // Index of the turn running at t_s, as segment_index_at; turns_ is not empty.
  std::size_t turn_index_at(double t_s) const;

  std::vector<TrajectorySegment> segments_;
  std::string description_;
  std::vector<Turn> turns_;  // empty: no orientation
};

// A built-in spec (see above) if the text before ':' names a built-in and no file of that name exists, otherwise the
// path of a CSV file. Throws TrajectoryError.
Trajectory load_trajectory(const std::string& spec_or_path);

// One finger of a several-finger device and the trajectory it plays (spidar_sim --finger NAME=TRAJECTORY).
struct NamedFinger {
  std::string name;
  Trajectory trajectory;
};
// Parses "NAME=TRAJECTORY" specs (TRAJECTORY as load_trajectory takes it): 1 to `max_fingers` of them, names
// non-empty and distinct. Throws TrajectoryError naming the spec.
std::vector<NamedFinger> parse_fingers(const std::vector<std::string>& specs, std::size_t max_fingers);
// Fingers made another way (trajectories from arrays): 1 to `max_fingers`, names non-empty and distinct. Throws
// TrajectoryError as parse_fingers does.
void check_fingers(const std::vector<NamedFinger>& fingers, std::size_t max_fingers);

// The parts of load_trajectory, for callers that know which they have.
Trajectory load_trajectory_csv(const std::string& path);
// The CSV format read from a stream (load_trajectory_csv opens the file and calls this); `source_name` stands for the
// file in error messages and becomes the description. Lets tests and the fuzzer feed text without a file.
Trajectory parse_trajectory_csv(std::istream& in, const std::string& source_name);
Trajectory make_builtin_trajectory(const std::string& spec);
bool is_builtin_trajectory_name(const std::string& name);

}  // namespace impetus
