// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/grip_sim.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

Eigen::Matrix<double, kGripStringCount, 1> as_vector(const GripTensions& tensions_N) {
  return Eigen::Map<const Eigen::Matrix<double, kGripStringCount, 1>>(tensions_N.data());
}

void check_tick(double dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) {
    throw std::invalid_argument("GripSim::tick: dt_s must be finite and > 0, got " + std::to_string(dt_s));
  }
}

GripPose start_of(const Trajectory& trajectory) {
  return {to_eigen(trajectory.position_at(0.0)), trajectory.orientation_at(0.0)};
}

}  // namespace

std::string grip_point_problem(const Eigen::Vector3d& point_m, const SpidarGripGeometry& geometry) {
  const double room_m = 0.5 * geometry.frame_side_m - geometry.grip_radius_m;
  const Eigen::Vector3d centre_m(geometry.centre_m[0], geometry.centre_m[1], geometry.centre_m[2]);
  if (!((point_m - centre_m).cwiseAbs().maxCoeff() > room_m)) return {};
  char message[256];
  std::snprintf(message, sizeof message,
                "the grip's target (%.4f, %.4f, %.4f) m is within its radius of the frame's cube (side %.3f m about "
                "(%.3f, %.3f, %.3f) m) or beyond: the strings cannot hold it there",
                point_m.x(), point_m.y(), point_m.z(), geometry.frame_side_m, centre_m.x(), centre_m.y(),
                centre_m.z());
  return message;
}

std::string grip_trajectory_problem(const Trajectory& trajectory, const SpidarGripGeometry& geometry) {
  auto outside = [&](double t_s, std::string& problem) {
    problem = grip_point_problem(to_eigen(trajectory.position_at(t_s)), geometry);
    if (problem.empty()) return false;
    char when[48];
    std::snprintf(when, sizeof when, "at t = %.3f s ", t_s);
    problem = when + problem;
    return true;
  };
  // A line stays between its ends, inside the cube if they are (it is convex); an arc is sampled 64 times, where its
  // chord's bulge is under 0.1 % of its radius.
  constexpr int kArcSamples = 64;
  std::string problem;
  for (const TrajectorySegment& segment : trajectory.segments()) {
    const int samples = segment.path == TrajectorySegment::Path::arc ? kArcSamples : 1;
    for (int i = 0; i <= samples; ++i) {
      const double t_s = segment.begin_s + (segment.end_s - segment.begin_s) * i / samples;
      if (outside(t_s, problem)) return problem;
    }
  }
  return problem;
}

GripSim::GripSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, Trajectory trajectory)
    : GripSim(geometry, hand, start_of(trajectory)) {
  const std::string problem = grip_trajectory_problem(trajectory, geometry);
  if (!problem.empty()) throw TrajectoryError(trajectory.description() + ": " + problem);
  trajectory_.emplace(std::move(trajectory));
}

GripSim::GripSim(const SpidarGripGeometry& geometry, const GripHandParams& hand, const GripPose& start)
    : strings_(geometry), hand_(hand, start) {
  if (!(geometry.tension_min_N >= 0.0 && geometry.tension_max_N >= geometry.tension_min_N &&
        std::isfinite(geometry.tension_max_N))) {
    throw std::invalid_argument("grip SPIDAR: tensions need 0 <= tension_min_N <= tension_max_N, finite");
  }
  tensions_N_.fill(geometry.tension_min_N);
  counts_ = strings_.encoder_counts(hand_.pose());
}

void GripSim::apply(const GripTensions& commanded_N) {
  const SpidarGripGeometry& geometry = strings_.geometry();
  for (int k = 0; k < kGripStringCount; ++k) {
    // A non-finite command is a broken servo: the motor holds its minimum, as when no command comes.
    const double command = std::isfinite(commanded_N[k]) ? commanded_N[k] : geometry.tension_min_N;
    tensions_N_[k] = std::clamp(command, geometry.tension_min_N, geometry.tension_max_N);
  }
}

void GripSim::substep(const GripPose& aim, const Eigen::Vector3d& aim_velocity_mps,
                      const Eigen::Vector3d& aim_angular_velocity_radps, double h_s) {
  const GripWrench device = strings_.wrench_matrix(hand_.pose()) * as_vector(tensions_N_);
  hand_.step(aim, aim_velocity_mps, aim_angular_velocity_radps, device, h_s);
}

const GripCounts& GripSim::tick(const GripTensions& commanded_N, const GripPose& target,
                                const Eigen::Vector3d& target_velocity_mps,
                                const Eigen::Vector3d& target_angular_velocity_radps, double dt_s) {
  check_tick(dt_s);
  apply(commanded_N);
  const int substeps = hand_.substeps_for(dt_s);
  const double h_s = dt_s / substeps;
  GripPose aim = target;
  for (int s = 0; s < substeps; ++s) {
    // The target over the tick: where it is at the tick's start, moved on by its velocities sub-step by sub-step.
    const double ahead_s = s * h_s;
    aim.position_m = target.position_m + ahead_s * target_velocity_mps;
    const Eigen::Vector3d turned = ahead_s * target_angular_velocity_radps;
    const double angle_rad = turned.norm();
    aim.orientation = angle_rad > 0.0
                          ? Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, turned / angle_rad)) * target.orientation
                          : target.orientation;
    substep(aim, target_velocity_mps, target_angular_velocity_radps, h_s);
  }
  time_s_ += dt_s;
  counts_ = strings_.encoder_counts(hand_.pose());
  return counts_;
}

const GripCounts& GripSim::tick(const GripTensions& commanded_N, double dt_s) {
  if (!trajectory_) throw std::logic_error("GripSim::tick: no trajectory to play (give the target instead)");
  check_tick(dt_s);
  apply(commanded_N);
  const int substeps = hand_.substeps_for(dt_s);
  const double h_s = dt_s / substeps;
  for (int s = 0; s < substeps; ++s) {
    const double t_s = trajectory_time_s() + s * h_s;
    const Trajectory::Sample sample = trajectory_->sample_at(t_s, segment_hint_);
    const GripPose aim{to_eigen(sample.position_m), trajectory_->orientation_at(t_s)};
    substep(aim, to_eigen(sample.velocity_mps), trajectory_->angular_velocity_at(t_s), h_s);
  }
  time_s_ += dt_s;
  counts_ = strings_.encoder_counts(hand_.pose());
  return counts_;
}

GripPose GripSim::trajectory_target() const {
  if (!trajectory_) return hand_.pose();
  return {to_eigen(trajectory_->position_at(trajectory_time_s())), trajectory_->orientation_at(trajectory_time_s())};
}

GripWrench GripSim::wrench() const { return strings_.wrench_matrix(hand_.pose()) * as_vector(tensions_N_); }

}  // namespace impetus
