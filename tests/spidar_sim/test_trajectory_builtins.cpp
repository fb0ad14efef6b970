// SPDX-License-Identifier: Apache-2.0
// Built-in trajectories: each shape starts, peaks and ends where its parameters say, moves with continuous velocity,
// and every parameter error names the key and the value.
#include "spidar_sim/trajectory.h"

#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

using impetus::load_trajectory;
using impetus::make_builtin_trajectory;
using impetus::to_eigen;
using impetus::Trajectory;
using impetus::TrajectoryError;

namespace {

constexpr double kSample_s = 1e-5;  // fine enough that a smooth velocity changes by < 1e-4 m/s between samples

Eigen::Vector3d at(const Trajectory& trajectory, double t_s) { return to_eigen(trajectory.position_at(t_s)); }
Eigen::Vector3d velocity(const Trajectory& trajectory, double t_s) { return to_eigen(trajectory.velocity_at(t_s)); }

// Velocity is continuous (no jump over one sample) and is the derivative of position, everywhere on the trajectory.
void check_smooth(const Trajectory& trajectory) {
  constexpr double kMaxJump_mps = 1e-3;
  double worst_jump = 0.0;
  double worst_derivative_error = 0.0;
  Eigen::Vector3d previous = velocity(trajectory, 0.0);
  for (double t = kSample_s; t <= trajectory.duration_s() + 0.01; t += kSample_s) {
    const Eigen::Vector3d v = velocity(trajectory, t);
    worst_jump = std::max(worst_jump, (v - previous).norm());
    previous = v;
    const Eigen::Vector3d difference = (at(trajectory, t + kSample_s) - at(trajectory, t - kSample_s)) / (2 * kSample_s);
    worst_derivative_error = std::max(worst_derivative_error, (difference - v).norm());
  }
  CHECK(worst_jump < kMaxJump_mps);
  CHECK(worst_derivative_error < kMaxJump_mps);
  CHECK(velocity(trajectory, 0.0).norm() == 0.0);                         // starts at rest
  CHECK(velocity(trajectory, trajectory.duration_s()).norm() == 0.0);     // ends at rest
}

// Largest value of coordinate `axis` (or its negation) over the trajectory.
double extreme(const Trajectory& trajectory, int axis, double sign) {
  double best = -1e9;
  for (double t = 0.0; t <= trajectory.duration_s(); t += kSample_s) best = std::max(best, sign * at(trajectory, t)[axis]);
  return sign * best;
}

double peak_speed(const Trajectory& trajectory, double from_s, double to_s) {
  double best = 0.0;
  for (double t = from_s; t <= to_s; t += kSample_s) best = std::max(best, velocity(trajectory, t).norm());
  return best;
}

void check_vec(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tolerance = 1e-12) {
  INFO("actual " << actual.transpose() << " expected " << expected.transpose());
  CHECK((actual - expected).norm() <= tolerance);
}

std::string error_of(const std::string& spec) {
  try {
    make_builtin_trajectory(spec);
  } catch (const TrajectoryError& error) {
    return error.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("tap defaults: start behind the face, peak at face_x + depth, strike at speed, withdraw and hold") {
  const Trajectory tap = load_trajectory("tap");
  const Eigen::Vector3d start(0.005 - 0.03, 0.0, 0.025);
  check_vec(at(tap, 0.0), start);
  CHECK(extreme(tap, 0, +1) == Approx(0.005 + 0.035).margin(1e-9));
  CHECK(extreme(tap, 0, -1) == Approx(start.x()).margin(1e-12));
  CHECK(extreme(tap, 1, +1) == 0.0);
  CHECK(extreme(tap, 2, +1) == Approx(0.025).margin(1e-15));
  CHECK(extreme(tap, 2, -1) == Approx(0.025).margin(1e-15));
  // The finger meets the face's rest position at `speed`, moving along +x.
  double t_face = 0.0;
  while (at(tap, t_face).x() < 0.005) t_face += kSample_s;
  check_vec(velocity(tap, t_face), Eigen::Vector3d(0.5, 0, 0), 1e-3);
  // Withdrawn to the start for the last `hold` seconds, and still there after the end.
  check_vec(at(tap, tap.duration_s() - 1.5), start);
  check_vec(at(tap, tap.duration_s() - 0.75), start);
  check_vec(at(tap, tap.duration_s() + 10.0), start);
  CHECK(peak_speed(tap, 0.0, tap.duration_s()) == Approx(0.5).epsilon(1e-6));
  check_smooth(tap);
}

TEST_CASE("tap parameters move the start, peak and hold") {
  const Trajectory tap = load_trajectory("tap:speed=1,depth=0.01,height=0.03,face_x=-0.02,y=0.015,standoff=0.05,hold=0.25");
  const Eigen::Vector3d start(-0.02 - 0.05, 0.015, 0.03);
  check_vec(at(tap, 0.0), start);
  CHECK(extreme(tap, 0, +1) == Approx(-0.02 + 0.01).margin(1e-9));
  check_vec(at(tap, tap.duration_s() - 0.25), start);
  CHECK(peak_speed(tap, 0.0, tap.duration_s()) == Approx(1.0).epsilon(1e-6));
  check_smooth(tap);
}

TEST_CASE("a tap with a rest waits at its start, then strikes as the tap without one") {
  const Trajectory tap = load_trajectory("tap");
  const Trajectory rested = load_trajectory("tap:rest=0.25");
  CHECK(rested.duration_s() == Approx(tap.duration_s() + 0.25).epsilon(1e-12));
  for (double t = 0.0; t <= 0.25; t += 0.01) check_vec(at(rested, t), at(tap, 0.0));
  CHECK(velocity(rested, 0.1).norm() == 0.0);
  for (double t = 0.0; t <= tap.duration_s(); t += 0.001) {
    INFO("t = " << t);
    CHECK((at(rested, t + 0.25) - at(tap, t)).norm() < 1e-9);
  }
  check_smooth(rested);
}

TEST_CASE("the documented example spec loads") {
  const Trajectory tap = load_trajectory("tap:speed=0.5,depth=0.035,height=0.025");
  CHECK(tap.description() == "tap:speed=0.5,depth=0.035,height=0.025");
  CHECK(tap.duration_s() > 1.5);
}

TEST_CASE("press: from above the surface down to depth below it, then hold") {
  const Trajectory press = load_trajectory("press:x=0.01,y=-0.02,surface_z=0.04,depth=0.005,standoff=0.02,hold=0.7");
  check_vec(at(press, 0.0), {0.01, -0.02, 0.06});
  const Eigen::Vector3d bottom(0.01, -0.02, 0.035);
  CHECK(extreme(press, 2, -1) == Approx(bottom.z()).margin(1e-9));
  check_vec(at(press, press.duration_s() - 0.7), bottom, 1e-12);
  check_vec(at(press, press.duration_s() + 1.0), bottom, 1e-12);
  CHECK(peak_speed(press, 0.0, press.duration_s()) == Approx(0.1).epsilon(1e-6));
  check_smooth(press);
}

TEST_CASE("slide: press, drag along x by distance at speed, hold") {
  for (const double distance : {0.05, -0.03}) {
    const std::string spec = "slide:x=0.01,surface_z=0.05,depth=0.004,distance=" + std::to_string(distance);
    INFO(spec);
    const Trajectory slide = load_trajectory(spec);
    check_vec(at(slide, 0.0), {0.01, 0.0, 0.08});
    CHECK(extreme(slide, 2, -1) == Approx(0.046).margin(1e-9));
    const Eigen::Vector3d end(0.01 + distance, 0.0, 0.046);
    check_vec(at(slide, slide.duration_s()), end, 1e-12);
    check_vec(at(slide, slide.duration_s() - 0.5), end, 1e-12);
    // x only ever moves toward the end, and never beyond it.
    double previous_x = at(slide, 0.0).x();
    bool monotone = true;
    for (double t = 0.0; t <= slide.duration_s(); t += 1e-3) {
      const double x = at(slide, t).x();
      monotone = monotone && (x - previous_x) * distance >= 0.0;
      previous_x = x;
    }
    CHECK(monotone);
    // The drag is the part after the press (whose own peak speed is press_speed = 0.1 m/s, along z).
    double drag_peak = 0.0;
    for (double t = 0.0; t <= slide.duration_s(); t += kSample_s) drag_peak = std::max(drag_peak, std::abs(velocity(slide, t).x()));
    CHECK(drag_peak == Approx(0.05).epsilon(1e-6));
    check_smooth(slide);
  }
}

TEST_CASE("circle: stays on the circle, full-speed laps take a period, starts and ends at rest") {
  const Trajectory circle = load_trajectory("circle:radius=0.02,period=0.5,cx=0.01,cy=0.02,cz=0.06,plane=xz,turns=3");
  const Eigen::Vector3d centre(0.01, 0.02, 0.06);
  check_vec(at(circle, 0.0), centre + Eigen::Vector3d(0.02, 0, 0));
  check_vec(at(circle, circle.duration_s()), centre + Eigen::Vector3d(0.02, 0, 0), 1e-12);
  // Ramps take one period each, the full-speed middle (turns − 1) periods.
  CHECK(circle.duration_s() == Approx(0.5 * (3 + 1)));
  double worst_radius_error = 0.0;
  double worst_off_plane = 0.0;
  double swept_rad = 0.0;
  Eigen::Vector3d previous = at(circle, 0.0) - centre;
  for (double t = kSample_s; t <= circle.duration_s(); t += kSample_s) {
    const Eigen::Vector3d r = at(circle, t) - centre;
    worst_radius_error = std::max(worst_radius_error, std::abs(r.norm() - 0.02));
    worst_off_plane = std::max(worst_off_plane, std::abs(r.y()));
    swept_rad += std::atan2(previous.x() * r.z() - previous.z() * r.x(), previous.dot(r));
    previous = r;
  }
  CHECK(worst_radius_error < 1e-12);
  CHECK(worst_off_plane < 1e-15);
  CHECK(swept_rad == Approx(3 * 2 * std::numbers::pi).epsilon(1e-9));  // counter-clockwise x → z, three laps
  CHECK(peak_speed(circle, 0.0, circle.duration_s()) == Approx(2 * std::numbers::pi * 0.02 / 0.5).epsilon(1e-6));
  check_smooth(circle);
}

TEST_CASE("every built-in parameter rejects a non-number, naming the key and the value") {
  const std::vector<std::pair<std::string, std::vector<std::string>>> builtins = {
      {"tap", {"speed", "depth", "height", "face_x", "y", "standoff", "hold", "rest"}},
      {"press", {"x", "y", "surface_z", "depth", "standoff", "speed", "hold"}},
      {"slide", {"x", "y", "surface_z", "depth", "standoff", "press_speed", "settle", "distance", "speed", "hold"}},
      {"circle", {"radius", "period", "cx", "cy", "cz", "turns"}},
  };
  for (const auto& [name, keys] : builtins) {
    for (const std::string& key : keys) {
      const std::string spec = name + ":" + key + "=1.5x";
      CHECK(error_of(spec) == name + ": " + key + "='1.5x': not a number");
      CHECK(error_of(name + ":" + key + "=nan") == name + ": " + key + "='nan': must be finite");
      CHECK_NOTHROW(make_builtin_trajectory(name + ":" + key + "=1.5"));  // the key itself is known
    }
  }
}

TEST_CASE("built-in parameter errors name the key and the value") {
  CHECK(error_of("tap:speed=-1") == "tap: speed='-1': must be > 0 (m/s)");
  CHECK(error_of("tap:depth=0") == "tap: depth='0': must be > 0 (m)");
  CHECK(error_of("tap:hold=-0.1") == "tap: hold='-0.1': must be >= 0 (s)");
  CHECK(error_of("tap:standoff=0") == "tap: standoff='0': must be > 0 (m)");
  CHECK(error_of("press:speed=0") == "press: speed='0': must be > 0 (m/s)");
  CHECK(error_of("slide:distance=0") == "slide: distance='0': must not be 0 (m)");
  CHECK(error_of("circle:turns=0.5") == "circle: turns='0.5': must be >= 1 (laps)");
  CHECK(error_of("circle:radius=0") == "circle: radius='0': must be > 0 (m)");
  CHECK(error_of("circle:plane=xw") == "circle: plane='xw': must be one of xy, xz, yz");
  CHECK(error_of("tap:sped=0.5") ==
        "tap: unknown parameter 'sped' (value '0.5'); known: speed, depth, height, face_x, y, standoff, hold, rest");
  CHECK(error_of("tap:speed=0.5,speed=0.6") == "tap: parameter 'speed' given twice (value '0.6')");
  CHECK(error_of("tap:speed") == "tap: parameter 'speed' has no value (expected key=value)");
  CHECK(error_of("tap:speed=0.5,,depth=0.01") == "tap: empty parameter in 'speed=0.5,,depth=0.01'");
  CHECK(error_of("bogus:speed=1") == "'bogus': unknown built-in trajectory; known: tap, press, slide, circle");
  CHECK_THROWS_AS(load_trajectory("tap:speed=abc"), TrajectoryError);
}

TEST_CASE("a sample with a segment hint is the sample without one, whatever the hint and the order of times") {
  for (const char* spec : {"tap", "tap:rest=0.3", "press", "slide", "circle:turns=2"}) {
    const Trajectory trajectory = load_trajectory(spec);
    std::size_t forward_hint = 0;
    std::size_t stale_hint = 7;  // a hint from nowhere: out of range for some, a wrong segment for others
    int mismatches = 0;
    // Forward in sub-step times, then backward, then jumping: the hint follows along or is wrong.
    std::vector<double> times;
    for (double t = -0.01; t <= trajectory.duration_s() + 0.01; t += 1e-4) times.push_back(t);
    for (double t = trajectory.duration_s() + 0.01; t >= -0.01; t -= 3.7e-3) times.push_back(t);
    for (int k = 0; k < 200; ++k) times.push_back(std::fmod(k * 0.618, trajectory.duration_s() + 0.02) - 0.01);
    for (const double t : times) {
      const Trajectory::Sample plain = trajectory.sample_at(t);
      const Trajectory::Sample followed = trajectory.sample_at(t, forward_hint);
      const Trajectory::Sample stale = trajectory.sample_at(t, stale_hint);
      stale_hint = 7;
      const bool same = plain.position_m == followed.position_m && plain.velocity_mps == followed.velocity_mps &&
                        plain.position_m == stale.position_m && plain.velocity_mps == stale.velocity_mps &&
                        plain.position_m == trajectory.position_at(t) && plain.velocity_mps == trajectory.velocity_at(t);
      mismatches += same ? 0 : 1;
    }
    INFO(spec << ": " << times.size() << " times");
    CHECK(mismatches == 0);
  }
}
