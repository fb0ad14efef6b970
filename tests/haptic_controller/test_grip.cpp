// SPDX-License-Identifier: Apache-2.0
// The 8-string grip SPIDAR's kinematics and tension distribution (haptic_controller/device/grip_kinematics.h,
// grip_tension.h): poses recovered from quantised string lengths, the failures named, force closure over the working
// volume, wrenches rendered exactly with the least tension, and the ones beyond the motors scaled, never distorted.

#include "haptic_controller/device/grip_kinematics.h"
#include "haptic_controller/device/grip_tension.h"

#include "tests/support/allocation_counter.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace impetus;
using Eigen::Vector3d;

namespace {

// Poses across the working volume: the grip's centre within ±6 cm of the frame's centre, turned up to 35° about a
// random axis (a hand's wrist does about that without regrasping).
GripPose random_pose(std::mt19937& random, const SpidarGripGeometry& geometry) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  GripPose pose;
  pose.position_m = Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]) +
                    0.06 * Vector3d(unit(random), unit(random), unit(random));
  const Vector3d axis = Vector3d(unit(random), unit(random), unit(random)).normalized();
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(35.0 * M_PI / 180.0 * unit(random), axis));
  return pose;
}

GripPose centre_pose(const SpidarGripGeometry& geometry) {
  GripPose pose;
  pose.position_m = Vector3d(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  return pose;
}

double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.inverse() * b).angle();
}

}  // namespace

TEST_CASE("the grip's pose comes back from its quantised string lengths, cold from the centre or warm") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  std::mt19937 random(7);
  int worst_cold_iterations = 0;
  double worst_position_m = 0.0;
  double worst_angle_rad = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const GripPose truth = random_pose(random, geometry);
    const GripLengths lengths = kinematics.lengths_m(kinematics.encoder_counts(truth));
    GripPose found;
    const GripSolve cold = kinematics.pose(lengths, centre_pose(geometry), found);
    REQUIRE(cold.status == GripSolveStatus::ok);
    worst_cold_iterations = std::max(worst_cold_iterations, cold.iterations);
    worst_position_m = std::max(worst_position_m, (found.position_m - truth.position_m).norm());
    worst_angle_rad = std::max(worst_angle_rad, angle_between(found.orientation, truth.orientation));
    // Half a count per string at most: the residual is quantisation.
    CHECK(cold.residual_rms_m <= 0.5 * geometry.metres_per_count);
    // Warm, from where the grip was a millisecond earlier at 0.5 m/s and 5 rad/s.
    GripPose before = truth;
    before.position_m -= Vector3d(3e-4, -2e-4, 2e-4);
    before.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.005, Vector3d::UnitZ())) * truth.orientation;
    const GripSolve warm = kinematics.pose(lengths, before, found);
    REQUIRE(warm.status == GripSolveStatus::ok);
    CHECK(warm.iterations <= 4);
  }
  INFO("worst position error " << worst_position_m << " m, angle " << worst_angle_rad << " rad, cold iterations "
                               << worst_cold_iterations);
  // A count is 17 µm; eight strings over a 2 cm grip: tens of µm and a few milliradians at most.
  CHECK(worst_position_m < 1e-4);
  CHECK(worst_angle_rad < 5e-3);
  CHECK(worst_cold_iterations <= 12);
}

TEST_CASE("a slack string, a non-finite length and a singular guess are named, not returned as a pose") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  const GripPose truth = centre_pose(geometry);
  GripLengths lengths = kinematics.lengths_m(truth);
  GripPose found;
  SECTION("one string 2 cm longer than any rigid pose allows (slack, or slipped on its pulley)") {
    lengths[3] += 0.02;
    const GripSolve solve = kinematics.pose(lengths, truth, found);
    CHECK(solve.status == GripSolveStatus::inconsistent);
    CHECK(solve.residual_rms_m > GripKinematics::kInconsistentCounts * geometry.metres_per_count);
  }
  SECTION("a NaN length") {
    lengths[5] = std::nan("");
    CHECK(kinematics.pose(lengths, truth, found).status == GripSolveStatus::not_finite);
  }
  SECTION("a grip whose attachments all sit at its centre fixes no orientation") {
    SpidarGripGeometry point = geometry;
    point.grip_radius_m = 0.0;
    const GripKinematics degenerate(point);
    CHECK(degenerate.pose(degenerate.lengths_m(truth), truth, found).status == GripSolveStatus::singular);
  }
  CHECK(std::string(to_string(GripSolveStatus::inconsistent)).find("string") != std::string::npos);
}

TEST_CASE("the grip is held in force closure over the working volume: zero wrench with every string taut") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  std::mt19937 random(11);
  for (int trial = 0; trial < 200; ++trial) {
    const GripPose pose = trial == 0 ? centre_pose(geometry) : random_pose(random, geometry);
    const GripWrenchMatrix w = kinematics.wrench_matrix(pose);
    // All six directions, well conditioned: torques taken at the grip's radius (as forces there), the smallest
    // singular value above a third of the largest (0.37 at worst in the geometry's scan).
    GripWrenchMatrix at_radius = w;
    at_radius.bottomRows<3>() /= geometry.grip_radius_m;
    const Eigen::JacobiSVD<GripWrenchMatrix> svd(at_radius);
    CHECK(svd.singularValues()(5) > svd.singularValues()(0) / 3.0);
    const GripTensionSolution rest =
        distribute_grip_tension(GripWrench::Zero(), w, geometry.tension_min_N, geometry.tension_max_N);
    REQUIRE(rest.closure);
    CHECK_FALSE(rest.saturated);
    CHECK(rest.achieved.norm() < 1e-7);
    for (double t : rest.tension_N) CHECK(t >= geometry.tension_min_N - 1e-9);
  }
}

TEST_CASE("a wrench within the motors is rendered exactly, with the least tension the limits allow") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double lo = geometry.tension_min_N;
  const double hi = geometry.tension_max_N;
  int exact = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const GripPose pose = random_pose(random, geometry);
    const GripWrenchMatrix w = kinematics.wrench_matrix(pose);
    GripWrench wrench;
    wrench << 5.0 * Vector3d(unit(random), unit(random), unit(random)),
        0.05 * Vector3d(unit(random), unit(random), unit(random));  // up to ~9 N and ~0.09 N·m
    const GripTensionSolution solution = distribute_grip_tension(wrench, w, lo, hi);
    REQUIRE(solution.closure);
    if (solution.saturated) continue;  // a corner of the volume where the motors fall short: the next test's case
    ++exact;
    CHECK((solution.achieved - wrench).norm() < 1e-7);
    double cost = 0.0;
    for (double t : solution.tension_N) {
      CHECK(t >= lo - 1e-9);
      CHECK(t <= hi + 1e-9);
      cost += t * t;
    }
    // No other exact solution within the limits has less tension: search the null space's plane around the answer
    // on a fine grid (a brute force that shares nothing with the candidates' geometry).
    Eigen::Matrix<double, 8, 1> t0;
    for (int k = 0; k < kGripStringCount; ++k) t0[k] = solution.tension_N[k];
    const Eigen::FullPivLU<GripWrenchMatrix> lu(w);
    const Eigen::MatrixXd kernel = lu.kernel();
    REQUIRE(kernel.cols() == 2);
    double best = cost;
    for (int i = -40; i <= 40; ++i) {
      for (int j = -40; j <= 40; ++j) {
        const Eigen::Matrix<double, 8, 1> t = t0 + 0.05 * (i * kernel.col(0) + j * kernel.col(1));
        if (t.minCoeff() >= lo && t.maxCoeff() <= hi) best = std::min(best, t.squaredNorm());
      }
    }
    CHECK(cost <= best + 1e-9);
  }
  CHECK(exact >= 80);  // most of these wrenches are within the motors anywhere in the volume
}

TEST_CASE("a wrench beyond the motors is scaled down, its direction kept, and the saturation said") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  const GripWrenchMatrix w = kinematics.wrench_matrix(centre_pose(geometry));
  GripWrench wrench;
  wrench << 200.0, -50.0, 80.0, 1.0, 0.0, -2.0;  // far beyond 8 × 20 N of string on a 2 cm grip
  const GripTensionSolution solution =
      distribute_grip_tension(wrench, w, geometry.tension_min_N, geometry.tension_max_N);
  REQUIRE(solution.closure);
  CHECK(solution.saturated);
  CHECK(solution.scale > 0.0);
  CHECK(solution.scale < 1.0);
  CHECK((solution.achieved - solution.scale * wrench).norm() < 1e-6 * wrench.norm());
  // A motor at its limit is what stopped the scale (the scale is exact: to rounding, micronewtons).
  double highest_N = 0.0;
  for (double t : solution.tension_N) highest_N = std::max(highest_N, t);
  INFO("highest tension " << highest_N << " N, scale " << solution.scale);
  CHECK(highest_N > geometry.tension_max_N - 1e-6);
  // A little more than the scale found cannot be rendered, a little less can, exactly.
  const GripTensionSolution more =
      distribute_grip_tension((solution.scale * (1.0 + 1e-6)) * wrench, w, geometry.tension_min_N,
                              geometry.tension_max_N);
  CHECK(more.saturated);
  const GripTensionSolution less =
      distribute_grip_tension((solution.scale * (1.0 - 1e-6)) * wrench, w, geometry.tension_min_N,
                              geometry.tension_max_N);
  CHECK_FALSE(less.saturated);
  SECTION("a non-finite wrench commands the minimum tensions") {
    wrench[2] = std::nan("");
    const GripTensionSolution none =
        distribute_grip_tension(wrench, w, geometry.tension_min_N, geometry.tension_max_N);
    for (double t : none.tension_N) CHECK(t == geometry.tension_min_N);
    CHECK_FALSE(none.closure);
  }
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("the grip's pose and tensions allocate nothing") {
  const SpidarGripGeometry geometry;
  const GripKinematics kinematics(geometry);
  std::mt19937 random(5);
  std::array<GripPose, 50> poses;
  for (GripPose& pose : poses) pose = random_pose(random, geometry);
  GripWrench wrench;
  wrench << 300.0, 2.0, -1.0, 0.01, 0.02, 0.5;  // saturated: the largest scale's search too
  impetus::test::start_counting_allocations();
  GripPose found = centre_pose(geometry);
  int saturated = 0;
  for (const GripPose& pose : poses) {
    kinematics.pose(kinematics.lengths_m(kinematics.encoder_counts(pose)), found, found);
    const GripTensionSolution solution = distribute_grip_tension(wrench, kinematics.wrench_matrix(found),
                                                                 geometry.tension_min_N, geometry.tension_max_N);
    saturated += solution.saturated ? 1 : 0;
  }
  REQUIRE(impetus::test::stop_counting_allocations() == 0);
  CHECK(saturated == static_cast<int>(poses.size()));
}
#endif
