// SPDX-License-Identifier: Apache-2.0
// A finger pressed diagonally into a concave corner of three static boxes whose faces touch exactly, in the whole
// loop (world, haptic, device in one process, 20 Hz world): the proxy stays in the corner and the force pushes out
// along all three walls, in every orientation of the corner. A wall whose plane came from the wrong face of its box
// lets the proxy slide along the seam into it, and one axis of the force goes missing.

#include "tests/integration/trial_support.h"
#include "loop/in_process_trial.h"
#include "tests/support/turns.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace impetus {
namespace {

using Eigen::Vector3d;

// The corner (corner frame): floor slab F under z = 0, wall W beyond x = 0, wall S beyond y = 0; free space is the
// octant x, y, z > 0. Centres and sizes, metres.
const std::array<std::pair<Vector3d, Vector3d>, 3> kBoxes{{{{0.05, 0.05, -0.025}, {0.1, 0.1, 0.05}},
                                                          {{-0.025, 0.025, 0.025}, {0.05, 0.15, 0.15}},
                                                          {{0.05, -0.025, 0.025}, {0.1, 0.05, 0.15}}}};
// The corner sits at the device's workspace centre (common/spidar/desktop_spidar.json).
const Vector3d kCorner_m(0.0, 0.0, 0.05);
// The hand's target starts 2 cm out along the diagonal and is driven 2 mm behind each wall (corner frame), then held.
constexpr double kStart_m = 0.02;
constexpr double kDepth_m = 0.002;

std::string json_vector(const Vector3d& v) {
  std::ostringstream out;
  out.precision(17);
  out << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return out.str();
}

void write_corner(const std::filesystem::path& dir, const Eigen::Quaterniond& turn) {
  std::ofstream scene(dir / "corner.json");
  scene.precision(17);
  scene << "{\"floor\": null, \"objects\": [";
  for (std::size_t i = 0; i < kBoxes.size(); ++i) {
    scene << (i ? ", " : "") << "{\"name\": \"" << "FWS"[i] << "\", \"shape\": \"box\", \"dynamic\": false, "
          << "\"size_m\": " << json_vector(kBoxes[i].second)
          << ", \"position_m\": " << json_vector(kCorner_m + turn * kBoxes[i].first) << ", \"orientation_wxyz\": ["
          << turn.w() << ", " << turn.x() << ", " << turn.y() << ", " << turn.z() << "]}";
  }
  scene << "]}\n";
  std::ofstream path(dir / "press.csv");
  path.precision(17);
  const Vector3d start = kCorner_m + turn * Vector3d::Constant(kStart_m);
  const Vector3d pressed = kCorner_m + turn * Vector3d::Constant(-kDepth_m);
  path << "t,x,y,z\n";
  for (const auto& [t, p] : {std::pair{0.0, start}, {0.6, pressed}, {1.2, pressed}}) {
    path << t << ',' << p.x() << ',' << p.y() << ',' << p.z() << '\n';
  }
}

// Columns of a log by name.
struct Log {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    FAIL("no column " << name);
    return 0;
  }
  Vector3d vector(std::size_t row, const std::string& prefix, const std::string& suffix) const {
    return {rows[row][column(prefix + "x" + suffix)], rows[row][column(prefix + "y" + suffix)], rows[row][column(prefix + "z" + suffix)]};
  }
};

Log read_log(const std::filesystem::path& path) {
  std::ifstream in(path);
  Log log;
  std::string line;
  std::getline(in, line);
  for (std::stringstream cells(line); std::getline(cells, line, ',');) log.header.push_back(line);
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (std::stringstream cells(line); std::getline(cells, line, ',');) row.push_back(std::stod(line));
    log.rows.push_back(row);
  }
  return log;
}

// How deep a corner-frame point is inside the walls: its distance to the free octant. Within 5 cm of the corner the
// three boxes fill everything outside the octant, seams included (a proxy sliding along a seam is inside the solid,
// though on the surface of each box alone).
double depth_in_walls_m(const Vector3d& p) { return p.cwiseMin(0.0).norm(); }

// The 24 axis turns and 6 random ones (tests/support/turns.h).
std::vector<Eigen::Quaterniond> turns() { return test::axis_and_random_turns(6, 7); }

}  // namespace

TEST_CASE("a finger pressed into a concave corner of touching boxes is held by all three walls, in every orientation") {
  int index = 0;
  for (const Eigen::Quaterniond& turn : turns()) {
    const std::filesystem::path dir = test::out_dir("corner-" + std::to_string(index++));
    write_corner(dir, turn);
    InProcessTrialOptions options;
    options.scene_path = (dir / "corner.json").string();
    options.trajectory = (dir / "press.csv").string();
    options.out_dir = dir;
    run_in_process_trial(options);

    const Log haptic = read_log(dir / "haptic.csv");
    REQUIRE(haptic.rows.size() > 1000);
    const std::size_t flags = haptic.column("flags");
    double deepest_m = 0.0;
    std::vector<std::size_t> held;  // ticks with a finger (the last row, after the device left, has none)
    for (std::size_t row = 0; row < haptic.rows.size(); ++row) {
      if ((static_cast<int>(haptic.rows[row][flags]) & 1) == 0) continue;
      const Vector3d proxy = turn.conjugate() * (haptic.vector(row, "proxy_", "_m") - kCorner_m);
      deepest_m = std::max(deepest_m, depth_in_walls_m(proxy));
      held.push_back(row);
    }
    REQUIRE(held.size() > 1000);
    // The last 0.2 s of the hold, in the corner frame: the finger's mean position and the mean force.
    Vector3d finger = Vector3d::Zero(), force = Vector3d::Zero();
    for (std::size_t k = held.size() - 200; k < held.size(); ++k) {
      finger += turn.conjugate() * (haptic.vector(held[k], "finger_", "_m") - kCorner_m) / 200.0;
      force += turn.conjugate() * haptic.vector(held[k], "force_", "_N") / 200.0;
    }
    INFO("turn " << turn.coeffs().transpose() << ": proxy up to " << deepest_m * 1e3 << " mm inside the walls; finger "
                 << finger.transpose() * 1e3 << " mm, force " << force.transpose() << " N (corner frame)");
    // The proxy lies on the walls' planes; only rounding may put it inside (1 µm is a thousand times that).
    CHECK(deepest_m < 1e-6);
    // Each wall is a spring on its own axis: force = K · the finger's depth behind it (the scene's default K,
    // 2000 N/m; the finger is at rest, so the damper adds nothing). The hand (300 N/m) holds the finger ~0.26 mm in.
    constexpr double kStiffness_Npm = 2000.0;
    for (int axis = 0; axis < 3; ++axis) {
      CHECK(finger[axis] < -1e-4);  // behind every wall
      CHECK(force[axis] == Approx(-kStiffness_Npm * finger[axis]).epsilon(0.05));
    }
  }
}

}  // namespace impetus
