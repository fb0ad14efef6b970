// SPDX-License-Identifier: Apache-2.0
#pragma once
// The 8-string SPIDAR that holds a grip (the SPIDAR-G family) as both the simulated hardware and the haptic
// controller's driver see it: one description, so the two cannot disagree about the frame.
//
// Frame geometry (world frame, z up, SI): the device frame is a cube of side `frame_side_m` centred on `centre_m`; a
// motor (pulley, encoder) sits at each of its eight corners, motor k at centre + ½·side·s_k with
// s_k = (±1, ±1, ±1), x the fastest-changing sign (k = 0: (−,−,−), k = 1: (+,−,−), ..., k = 7: (+,+,+)). String k
// runs from motor k to an attachment point a_k on the grip, in the grip's own frame (origin its centre):
//   a_k = grip_radius_m/√3 · Rz(±kTurn_rad)·s_k, + where s_x·s_y·s_z > 0 and − elsewhere,
// the corner's direction turned a third of a turn about z, the two ways in a checkerboard over the corners. Why:
// strings aimed at the grip's centre (a_k ∥ s_k) give no torque at all; turned one way above and the other below, or
// all one way, the eight wrench columns span only five directions (a symmetry leaves one torque out). The
// checkerboard spans all six, and a third of a turn was the best of a scan of the angle (docs/devices.md §8): over
// the working volume (±6 cm, turned ±35°) the wrench matrix, torques taken at the grip's radius, keeps its smallest
// singular value above a third of its largest, and a positive balance of tensions holds the grip at rest (force
// closure; tests/haptic_controller/test_grip.cpp checks both).

#include "common/contract/vec3.h"
#include "common/spidar/device_file.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace impetus {

inline constexpr int kGripStringCount = 8;

struct SpidarGripGeometry {
  double frame_side_m = 0.4;        // as the 4-string desktop SPIDAR's (common/spidar/geometry.h)
  Vec3 centre_m{0.0, 0.0, 0.05};
  double grip_radius_m = 0.02;      // a ball held in the fingertips
  double metres_per_count = 1.7e-5; // string length per encoder count
  double tension_min_N = 0.5;       // strings must stay taut or the length reading is lost
  double tension_max_N = 20.0;      // motor torque limit over the pulley radius

  // Motor k's string exit, world frame.
  Eigen::Vector3d motor_m(int k) const {
    const double h = 0.5 * frame_side_m;
    return Eigen::Vector3d(centre_m[0], centre_m[1], centre_m[2]) + h * corner_sign(k);
  }
  // String k's attachment point on the grip, grip frame.
  Eigen::Vector3d attachment_m(int k) const {
    constexpr double kTurn_rad = 2.0 * 3.14159265358979323846 / 3.0;
    const Eigen::Vector3d s = corner_sign(k);
    const double turn = s.x() * s.y() * s.z() > 0.0 ? kTurn_rad : -kTurn_rad;
    const Eigen::Vector3d turned(std::cos(turn) * s.x() - std::sin(turn) * s.y(),
                                 std::sin(turn) * s.x() + std::cos(turn) * s.y(), s.z());
    return grip_radius_m / std::sqrt(3.0) * turned;
  }
  static Eigen::Vector3d corner_sign(int k) {
    return Eigen::Vector3d((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
  }
};

// A grip device description file (JSON, e.g. common/spidar/desktop_grip.json): the fields of SpidarGripGeometry, each
// optional (a missing one keeps its default above). Unknown keys and unusable values are errors naming the file and
// the key (device_file.h). Throws SpidarGeometryError.
SpidarGripGeometry load_grip_geometry(const std::string& path);

// `grip` (the built-in geometry above) or `grip:FILE.json` (the device registry's "grip", Python's ToolSimulation).
struct GripDevice {
  SpidarGripGeometry geometry;
  std::string source = "built-in";  // the file it came from, for messages
};
GripDevice parse_grip_spec(const std::string& spec);

// A hash of the values (not the file's text): two descriptions with equal values are the same device.
std::uint64_t grip_geometry_hash(const SpidarGripGeometry& geometry);

}  // namespace impetus
