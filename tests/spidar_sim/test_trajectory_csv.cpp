// SPDX-License-Identifier: Apache-2.0
// CSV trajectories: interpolation, holding outside the time range, and error messages that point at line and column.
#include "spidar_sim/trajectory.h"
#include "trajectory_test_util.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>

using impetus::load_trajectory;
using impetus::load_trajectory_csv;
using impetus::TrajectoryError;
using impetus::Vec3;
using impetus::test::TempFile;

namespace {

// The error message for a CSV with this content, with the temporary path replaced by "FILE".
std::string csv_error(const std::string& content) {
  const TempFile file("trajectory.csv", content);
  try {
    load_trajectory_csv(file.path());
  } catch (const TrajectoryError& error) {
    std::string message = error.what();
    const std::string path = file.path();
    if (message.rfind(path, 0) == 0) message.replace(0, path.size(), "FILE");
    return message;
  }
  return "no error";
}

void check_near(const Vec3& actual, const Vec3& expected, double tolerance = 1e-12) {
  for (int a = 0; a < 3; ++a) CHECK(actual[a] == Approx(expected[a]).margin(tolerance));
}

}  // namespace

TEST_CASE("csv trajectory interpolates linearly and holds the end points") {
  const TempFile file("ok.csv", "t,x,y,z\n0.5,0,0,0\n1.5,1,-2,4\r\n\n2.5,1,0,4\n");
  const auto trajectory = load_trajectory_csv(file.path());
  CHECK(trajectory.duration_s() == 2.5);
  check_near(trajectory.position_at(0.0), {0, 0, 0});    // before the first point: hold it
  check_near(trajectory.position_at(1.0), {0.5, -1, 2});
  check_near(trajectory.position_at(1.5), {1, -2, 4});
  check_near(trajectory.position_at(2.0), {1, -1, 4});
  check_near(trajectory.position_at(10.0), {1, 0, 4});   // after the last point: hold it
  check_near(trajectory.velocity_at(1.0), {1, -2, 4});
  check_near(trajectory.velocity_at(0.2), {0, 0, 0});
  check_near(trajectory.velocity_at(3.0), {0, 0, 0});
}

TEST_CASE("csv trajectory with one waypoint holds it") {
  const TempFile file("one.csv", "t,x,y,z\n0, 0.1, 0.2, 0.3\n");
  const auto trajectory = load_trajectory_csv(file.path());
  CHECK(trajectory.duration_s() == 0.0);
  check_near(trajectory.position_at(0.0), {0.1, 0.2, 0.3});
  check_near(trajectory.position_at(5.0), {0.1, 0.2, 0.3});
}

TEST_CASE("csv errors name the file, line, column and column name") {
  CHECK(csv_error("0,0,0,0\n") ==
        "FILE:1:1 (header): expected the header 't,x,y,z' (or 't,x,y,z,qw,qx,qy,qz') (got '0,0,0,0')");
  CHECK(csv_error("t,x,y,w\n0,0,0,0\n") ==
        "FILE:1:7 (header): expected the header 't,x,y,z' (or 't,x,y,z,qw,qx,qy,qz') (got 't,x,y,w')");
  CHECK(csv_error("") == "FILE:1:1 (header): empty file: expected the header 't,x,y,z' (got '')");
  CHECK(csv_error("t,x,y,z\n") == "FILE:2:1 (t): no waypoints after the header (got '')");
  CHECK(csv_error("t,x,y,z\n0,0,0,0\n0,1,1,1\n") ==
        "FILE:3:1 (t): time must be strictly increasing (line 2 has t = 0) (got '0')");
  CHECK(csv_error("t,x,y,z\n1,0,0,0\n\n0.5,1,1,1\n") ==
        "FILE:4:1 (t): time must be strictly increasing (line 2 has t = 1) (got '0.5')");
  CHECK(csv_error("t,x,y,z\n0,0,nan,0\n") == "FILE:2:5 (y): value must be finite (got 'nan')");
  CHECK(csv_error("t,x,y,z\n0,0,0,inf\n") == "FILE:2:7 (z): value must be finite (got 'inf')");
  CHECK(csv_error("t,x,y,z\n0,1,2\n") ==
        "FILE:2:6 (z): missing value: expected 4 columns t,x,y,z (got '0,1,2')");
  CHECK(csv_error("t,x,y,z\n0\n") == "FILE:2:2 (x): missing value: expected 4 columns t,x,y,z (got '0')");
  CHECK(csv_error("t,x,y,z\n0,1,2,3,4\n") ==
        "FILE:2:9 (extra): too many columns: expected 4 columns t,x,y,z (got '4')");
  CHECK(csv_error("t,x,y,z\n0,1,2x,3\n") == "FILE:2:5 (y): not a number (got '2x')");
  CHECK(csv_error("t,x,y,z\n0,  abc ,2,3\n") == "FILE:2:5 (x): not a number (got 'abc')");
  CHECK(csv_error("t,x,y,z\n0,,2,3\n") == "FILE:2:3 (x): not a number (got '')");
  CHECK(csv_error("t,x,y,z\n-1,0,0,0\n") ==
        "FILE:2:1 (t): time must be >= 0 (the session starts at t = 0) (got '-1')");
}

TEST_CASE("missing trajectory file is an error naming the path") {
  const std::string path = (std::filesystem::temp_directory_path() / "impetus_no_such_trajectory.csv").string();
  CHECK_THROWS_WITH(load_trajectory(path), Catch::Contains(path) && Catch::Contains("cannot open"));
}

TEST_CASE("a file named like a built-in is read as a file") {
  const auto previous = std::filesystem::current_path();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("impetus_spidar_sim_shadow_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::current_path(dir);
  std::ofstream("tap") << "t,x,y,z\n0,7,8,9\n";
  Vec3 start{};
  try {
    start = load_trajectory("tap").position_at(0.0);
  } catch (...) {
    std::filesystem::current_path(previous);
    throw;
  }
  std::filesystem::current_path(previous);
  std::filesystem::remove_all(dir);
  check_near(start, {7, 8, 9});
}

TEST_CASE("csv trajectory with orientation turns at constant angular velocity between waypoints, the shorter way") {
  // A quarter turn about z over 1 s, then back half of it over 0.5 s written with the quaternion's other sign (the
  // same orientation): the turn taken is the shorter one, not the long way round.
  const double half = std::sqrt(0.5);
  const TempFile file("turn.csv", "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n1,0.1,0,0," + std::to_string(half) + ",0,0," +
                                      std::to_string(half) + "\n1.5,0.1,0,0,-0.9238795,0,0,-0.3826834\n");
  const auto trajectory = load_trajectory_csv(file.path());
  REQUIRE(trajectory.turns());
  const double quarter = 3.14159265358979323846 / 2.0;
  const Eigen::AngleAxisd at_half(trajectory.orientation_at(0.5));
  CHECK(at_half.angle() == Approx(quarter / 2.0).margin(1e-6));
  CHECK(at_half.axis().isApprox(Eigen::Vector3d::UnitZ(), 1e-9));
  CHECK(trajectory.angular_velocity_at(0.5).isApprox(Eigen::Vector3d(0, 0, quarter), 1e-5));
  CHECK(trajectory.angular_velocity_at(1.2).isApprox(Eigen::Vector3d(0, 0, -quarter / 2.0 / 0.5), 1e-5));
  CHECK(trajectory.angular_velocity_at(2.0) == Eigen::Vector3d::Zero());  // held after the last waypoint
  CHECK(Eigen::AngleAxisd(trajectory.orientation_at(5.0)).angle() == Approx(quarter / 2.0).margin(1e-6));
  CHECK(trajectory.orientation_at(-1.0).isApprox(Eigen::Quaterniond::Identity()));
  check_near(trajectory.position_at(0.5), {0.05, 0, 0});
  // The orientation is the time integral of the angular velocity: a turn of the 1 ms steps a device takes.
  Eigen::Quaterniond integrated = trajectory.orientation_at(0.0);
  for (int tick = 0; tick < 1500; ++tick) {
    const Eigen::Vector3d step = 1e-3 * trajectory.angular_velocity_at(1e-3 * (tick + 0.5));
    if (step.norm() > 0.0) {
      integrated = Eigen::Quaterniond(Eigen::AngleAxisd(step.norm(), step.normalized())) * integrated;
    }
  }
  CHECK(integrated.angularDistance(trajectory.orientation_at(1.5)) < 1e-9);
  // Held longer (a device of several fingers), it keeps its turns.
  CHECK(trajectory.held_until(3.0).orientation_at(2.5).isApprox(trajectory.orientation_at(1.5)));
}

TEST_CASE("csv trajectory without orientation columns does not turn, and a bad quaternion names its line and column") {
  const TempFile file("still.csv", "t,x,y,z\n0,0,0,0\n1,0.1,0,0\n");
  const auto still = load_trajectory_csv(file.path());
  CHECK_FALSE(still.turns());
  CHECK(still.orientation_at(0.5).isApprox(Eigen::Quaterniond::Identity()));
  CHECK(still.angular_velocity_at(0.5) == Eigen::Vector3d::Zero());
  CHECK(csv_error("t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n1,0,0,0,0.5,0.5,0,0\n") ==
        "FILE:3:9 (qw): the orientation must be a unit quaternion qw,qx,qy,qz (its norm is 0.707107) (got "
        "'0.5,0.5,0,0')");
  CHECK(csv_error("t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0\n") ==
        "FILE:2:14 (qz): missing value: expected 8 columns t,x,y,z,qw,qx,qy,qz (got '0,0,0,0,1,0,0')");
  CHECK(csv_error("t,x,y,z\n0,0,0,0,1\n") ==
        "FILE:2:9 (extra): too many columns: expected 4 columns t,x,y,z (got '1')");
}
