// SPDX-License-Identifier: Apache-2.0
#pragma once
// The SPIDAR device as both sides see it: the haptic controller's driver (kinematics, tension distribution) and the
// simulated hardware in spidar_sim use this one description, so they cannot disagree about the frame.
//
// Frame geometry: the device frame is a cube of side `frame_side_m` centred on `centre_m` (world frame, z up). The four
// motors (with pulley and encoder) sit at alternate corners of the cube, i.e. the vertices of a regular tetrahedron:
//   (+,+,+), (+,−,−), (−,+,−), (−,−,+)   times frame_side_m/2 from the centre.
// Each string runs from its motor's pulley exit point to the finger cap. A string pulls the finger toward its motor
// with the tension it carries; strings can only pull, so any force needs a positive combination of the four unit
// vectors, which the tetrahedral layout provides everywhere inside the frame.

#include "common/contract/frames.h"
#include "common/contract/vec3.h"
#include "common/spidar/device_file.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace impetus {

struct SpidarGeometry {
  double frame_side_m = 0.4;          // cube side: a desktop SPIDAR's working volume
  Vec3 centre_m{0.0, 0.0, 0.05};      // the workspace centre in the world frame (5 cm above the floor of the scenes)
  double metres_per_count = 1.7e-5;   // string length per encoder count (pulley circumference / counts per turn)
  double tension_min_N = 0.5;         // strings must stay taut or the length reading is lost
  double tension_max_N = 20.0;        // motor torque limit over the pulley radius
  // Largest force the driver will render; larger forces are clamped (and counted) before mapping. With the
  // tetrahedral layout and tensions in [0.5, 20] N a force of this size is feasible in every direction at the centre;
  // about 5 cm off centre some directions top out near 9.3 N, and the tension distribution renders the nearest
  // feasible force and counts a saturation (the hard cases report saturations; none of them reach one).
  double max_force_N = 10.0;

  // Motor (string exit) positions in the world frame, derived from the fields above.
  std::array<Vec3, kStringCount> motor_positions_m() const {
    const double h = 0.5 * frame_side_m;
    constexpr int signs[kStringCount][3] = {{+1, +1, +1}, {+1, -1, -1}, {-1, +1, -1}, {-1, -1, +1}};
    std::array<Vec3, kStringCount> motors{};
    for (int i = 0; i < kStringCount; ++i) {
      for (int a = 0; a < 3; ++a) motors[i][a] = centre_m[a] + signs[i][a] * h;
    }
    return motors;
  }
};

// A device description file (JSON, e.g. common/spidar/desktop_spidar.json): the fields of SpidarGeometry, each
// optional (a missing one keeps its default above). Unknown keys and unusable values are errors naming the file and
// the key. Throws SpidarGeometryError (device_file.h).
SpidarGeometry load_spidar_geometry(const std::string& path);

// `spidar` (the built-in geometry above) or `spidar:FILE.json` (--device on haptic_controller and spidar_sim).
struct SpidarDevice {
  SpidarGeometry geometry;
  std::string source = "built-in";  // the file it came from, for messages
};
SpidarDevice parse_device_spec(const std::string& spec);

// A hash of the values (not the file's text): two descriptions with equal values are the same device.
std::uint64_t geometry_hash(const SpidarGeometry& geometry);

}  // namespace impetus
