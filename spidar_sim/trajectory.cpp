// SPDX-License-Identifier: Apache-2.0
#include "spidar_sim/trajectory.h"

#include "common/runtime/message_text.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <span>
#include <sstream>
#include <string_view>

namespace impetus {

namespace {

constexpr double kPi = std::numbers::pi;
// Consecutive segments must join: a gap this large (m) means a builder bug, not rounding.
constexpr double kJoinTolerance_m = 1e-9;

// ---------------------------------------------------------------------------------------------------------------
// Evaluation

// s(τ) and ds/dτ of each easing (see Easing in the header).
double eased_fraction(Easing easing, double tau) {
  switch (easing) {
    case Easing::linear: return tau;
    case Easing::smooth: return 0.5 * (1.0 - std::cos(kPi * tau));
    case Easing::accelerate: return tau - std::sin(kPi * tau) / kPi;
    case Easing::decelerate: return tau + std::sin(kPi * tau) / kPi;
  }
  return tau;
}

double eased_rate(Easing easing, double tau) {
  switch (easing) {
    case Easing::linear: return 1.0;
    case Easing::smooth: return 0.5 * kPi * std::sin(kPi * tau);
    case Easing::accelerate: return 1.0 - std::cos(kPi * tau);
    case Easing::decelerate: return 1.0 + std::cos(kPi * tau);
  }
  return 1.0;
}

double arc_angle(const TrajectorySegment& seg, double s) {
  return seg.begin_angle_rad + (seg.end_angle_rad - seg.begin_angle_rad) * s;
}

Eigen::Vector3d point_on_path(const TrajectorySegment& seg, double s) {
  if (seg.path == TrajectorySegment::Path::line) {
    return to_eigen(seg.from_m) + s * (to_eigen(seg.to_m) - to_eigen(seg.from_m));
  }
  const double theta = arc_angle(seg, s);
  return to_eigen(seg.centre_m) +
         seg.radius_m * (std::cos(theta) * to_eigen(seg.axis_u) + std::sin(theta) * to_eigen(seg.axis_v));
}

// dP/ds: the path's tangent scaled by its length.
Eigen::Vector3d path_derivative(const TrajectorySegment& seg, double s) {
  if (seg.path == TrajectorySegment::Path::line) return to_eigen(seg.to_m) - to_eigen(seg.from_m);
  const double theta = arc_angle(seg, s);
  const double sweep = seg.end_angle_rad - seg.begin_angle_rad;
  return seg.radius_m * sweep * (-std::sin(theta) * to_eigen(seg.axis_u) + std::cos(theta) * to_eigen(seg.axis_v));
}

double segment_tau(const TrajectorySegment& seg, double t_s) {
  const double span = seg.end_s - seg.begin_s;
  if (span <= 0.0) return 1.0;
  return std::clamp((t_s - seg.begin_s) / span, 0.0, 1.0);
}

bool segment_finite(const TrajectorySegment& seg) {
  return std::isfinite(seg.begin_s) && std::isfinite(seg.end_s) && all_finite(seg.from_m) && all_finite(seg.to_m) &&
         all_finite(seg.centre_m) && all_finite(seg.axis_u) && all_finite(seg.axis_v) && std::isfinite(seg.radius_m) &&
         std::isfinite(seg.begin_angle_rad) && std::isfinite(seg.end_angle_rad);
}

// Finite parameters can still overflow when evaluated: a line from −1e308 to 1e308 has an infinite length, a circle
// of radius 1e308 around x = 1e308 leaves the doubles, and a step of 1e−320 s has an infinite speed. Bounds every
// intermediate of point_on_path and velocity_at (|cos|, |sin| <= 1, s in [0, 1], ds/dτ <= 2 for every easing),
// so a trajectory that passes evaluates to finite numbers at any time.
bool segment_evaluable(const TrajectorySegment& seg) {
  constexpr double kMaxEasedRate = 2.0;  // accelerate/decelerate peak; smooth peaks at π/2, linear at 1
  Eigen::Vector3d reach;                 // bound on |P(s)| per component
  Eigen::Vector3d rate;                  // bound on |dP/ds| per component
  if (seg.path == TrajectorySegment::Path::line) {
    const Eigen::Vector3d delta = to_eigen(seg.to_m) - to_eigen(seg.from_m);
    reach = to_eigen(seg.from_m).cwiseAbs() + delta.cwiseAbs();
    rate = delta.cwiseAbs();
  } else {
    const double sweep = seg.end_angle_rad - seg.begin_angle_rad;
    const Eigen::Vector3d axes = to_eigen(seg.axis_u).cwiseAbs() + to_eigen(seg.axis_v).cwiseAbs();
    reach = to_eigen(seg.centre_m).cwiseAbs() + seg.radius_m * axes;
    rate = std::abs(seg.radius_m * sweep) * axes;
  }
  if (!reach.allFinite() || !rate.allFinite()) return false;
  const double span = seg.end_s - seg.begin_s;
  if (!(span > 0.0)) return true;  // velocity_at does not divide by an empty span
  const double per_second = kMaxEasedRate / span;
  return std::isfinite(per_second) && (rate * per_second).allFinite();
}

// ---------------------------------------------------------------------------------------------------------------
// Shared parsing helpers

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

enum class NumberStatus { ok, not_a_number, not_finite };

NumberStatus parse_number(std::string_view text, double& value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);  // from_chars rejects an explicit '+'
  if (text.empty()) return NumberStatus::not_a_number;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec == std::errc::result_out_of_range) return NumberStatus::not_finite;
  if (ec != std::errc() || ptr != end) return NumberStatus::not_a_number;
  if (!std::isfinite(value)) return NumberStatus::not_finite;
  return NumberStatus::ok;
}

// ---------------------------------------------------------------------------------------------------------------
// CSV files

constexpr std::string_view kCsvHeader = "t,x,y,z";
constexpr std::string_view kCsvTurningHeader = "t,x,y,z,qw,qx,qy,qz";
constexpr std::array<std::string_view, 8> kCsvColumns = {"t", "x", "y", "z", "qw", "qx", "qy", "qz"};
// A quaternion written by hand or by a script to a few digits is unit to 10⁻³; one further off is a column mix-up or
// a rotation written some other way (Euler angles), not rounding.
constexpr double kUnitQuaternionTolerance = 1e-3;

[[noreturn]] void csv_error(const std::string& path, int line, std::size_t column, std::string_view column_name,
                            std::string_view reason, std::string_view got) {
  std::ostringstream message;
  message << path << ':' << line << ':' << column << " (" << column_name << "): " << reason << " (got '" << excerpt(got, 80)
          << "')";
  throw TrajectoryError(message.str());
}

struct CsvField {
  std::string_view text;  // trimmed
  std::size_t column;     // 1-based character column of the field's first non-blank character
};

// Splits one data line into fields; keeps columns so errors can point at them.
std::vector<CsvField> split_fields(std::string_view line) {
  std::vector<CsvField> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string_view raw = line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
    const std::size_t lead = std::min(raw.find_first_not_of(" \t"), raw.size());
    fields.push_back({trim(raw), start + lead + 1});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Trajectory

Trajectory::Trajectory(std::vector<TrajectorySegment> segments, std::string description)
    : segments_(std::move(segments)), description_(std::move(description)) {
  if (segments_.empty()) throw TrajectoryError(excerpt(description_, 80) + ": trajectory has no segments");
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    const TrajectorySegment& seg = segments_[i];
    if (!segment_finite(seg)) throw TrajectoryError(excerpt(description_, 80) + ": segment " + std::to_string(i) + " is not finite");
    if (!segment_evaluable(seg)) {
      throw TrajectoryError(excerpt(description_, 80) + ": segment " + std::to_string(i) +
                            " has positions or speeds too large to represent");
    }
    if (seg.end_s < seg.begin_s) {
      throw TrajectoryError(excerpt(description_, 80) + ": segment " + std::to_string(i) + " ends before it begins");
    }
    if (i == 0) {
      if (seg.begin_s < 0.0) throw TrajectoryError(excerpt(description_, 80) + ": trajectory begins before t = 0");
      continue;
    }
    const TrajectorySegment& prev = segments_[i - 1];
    if (seg.begin_s != prev.end_s) {
      throw TrajectoryError(excerpt(description_, 80) + ": segment " + std::to_string(i) +
                            " does not begin when the previous ends");
    }
    if ((point_on_path(seg, 0.0) - point_on_path(prev, 1.0)).norm() > kJoinTolerance_m) {
      throw TrajectoryError(excerpt(description_, 80) + ": segment " + std::to_string(i) +
                            " does not begin where the previous ends");
    }
  }
}

Trajectory Trajectory::from_waypoints(const std::vector<Waypoint>& waypoints, std::string description,
                                      bool turning) {
  if (waypoints.empty()) throw TrajectoryError(excerpt(description, 80) + ": no waypoints");
  std::vector<TrajectorySegment> segments;
  const auto line_between = [](const Waypoint& a, const Waypoint& b) {
    TrajectorySegment seg;
    seg.begin_s = a.t_s;
    seg.end_s = b.t_s;
    seg.from_m = a.position_m;
    seg.to_m = b.position_m;
    return seg;
  };
  if (waypoints.size() == 1) {
    segments.push_back(line_between(waypoints[0], waypoints[0]));  // a point held forever
  }
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    if (!(waypoints[i].t_s > waypoints[i - 1].t_s)) {
      throw TrajectoryError(excerpt(description, 80) + ": waypoint " + std::to_string(i) + ": time must be strictly increasing");
    }
    segments.push_back(line_between(waypoints[i - 1], waypoints[i]));
  }
  Trajectory trajectory(std::move(segments), std::move(description));
  if (!turning) return trajectory;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Eigen::Quaterniond& q = waypoints[i].orientation;
    if (!q.coeffs().allFinite() || !(q.norm() > 0.0)) {
      throw TrajectoryError(excerpt(trajectory.description_, 80) + ": waypoint " + std::to_string(i) +
                            ": orientation must be a finite, non-zero quaternion");
    }
  }
  // Each turn from one waypoint's orientation to the next's, the shorter way, at constant angular velocity.
  Eigen::Quaterniond from = waypoints[0].orientation.normalized();
  if (waypoints.size() == 1) {
    trajectory.turns_.push_back({waypoints[0].t_s, waypoints[0].t_s, from, Eigen::Vector3d::Zero()});
  }
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    Eigen::Quaterniond to = waypoints[i].orientation.normalized();
    if (from.dot(to) < 0.0) to.coeffs() = -to.coeffs();
    const Eigen::AngleAxisd turn(to * from.conjugate());
    const double span_s = waypoints[i].t_s - waypoints[i - 1].t_s;
    trajectory.turns_.push_back({waypoints[i - 1].t_s, waypoints[i].t_s, from, turn.angle() / span_s * turn.axis()});
    from = to;
  }
  return trajectory;
}

std::size_t Trajectory::turn_index_at(double t_s) const {
  const auto it = std::upper_bound(turns_.begin(), turns_.end(), t_s,
                                   [](double t, const Turn& turn) { return t < turn.end_s; });
  return it == turns_.end() ? turns_.size() - 1 : static_cast<std::size_t>(it - turns_.begin());
}

Eigen::Quaterniond Trajectory::orientation_at(double t_s) const {
  if (turns_.empty()) return Eigen::Quaterniond::Identity();
  const Turn& turn = turns_[turn_index_at(t_s)];
  const double along_s = std::clamp(t_s - turn.begin_s, 0.0, turn.end_s - turn.begin_s);
  const Eigen::Vector3d turned = along_s * turn.angular_velocity_radps;
  const double angle_rad = turned.norm();
  if (!(angle_rad > 0.0)) return turn.from;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, turned / angle_rad)) * turn.from).normalized();
}

Eigen::Vector3d Trajectory::angular_velocity_at(double t_s) const {
  if (turns_.empty() || !(t_s >= turns_.front().begin_s) || t_s >= turns_.back().end_s) {
    return Eigen::Vector3d::Zero();
  }
  return turns_[turn_index_at(t_s)].angular_velocity_radps;
}

std::size_t Trajectory::segment_index_at(double t_s, std::size_t hint) const {
  // First segment still running at t_s; zero-length segments are never "running", so they are skipped. Ends never
  // decrease, so segment k is that one iff t_s < end_k and (k = 0 or t_s >= end_(k−1)): the hint and the segment
  // after it are checked so, before a binary search.
  for (std::size_t k = hint; k < segments_.size() && k <= hint + 1; ++k) {
    if (t_s < segments_[k].end_s && (k == 0 || !(t_s < segments_[k - 1].end_s))) return k;
  }
  const auto it = std::upper_bound(segments_.begin(), segments_.end(), t_s,
                                   [](double t, const TrajectorySegment& seg) { return t < seg.end_s; });
  return it == segments_.end() ? segments_.size() - 1 : static_cast<std::size_t>(it - segments_.begin());
}

Trajectory Trajectory::held_until(double end_s) const {
  if (!(end_s > duration_s())) return *this;
  std::vector<TrajectorySegment> segments = segments_;
  TrajectorySegment hold;
  hold.begin_s = duration_s();
  hold.end_s = end_s;
  hold.from_m = position_at(duration_s());
  hold.to_m = hold.from_m;
  segments.push_back(hold);
  Trajectory held(std::move(segments), description_);
  held.turns_ = turns_;  // the last orientation holds after the last turn as after the last point
  return held;
}

Vec3 Trajectory::position_at(double t_s) const { return sample_at(t_s).position_m; }

Vec3 Trajectory::velocity_at(double t_s) const { return sample_at(t_s).velocity_mps; }

Trajectory::Sample Trajectory::sample_at(double t_s) const {
  std::size_t hint = 0;
  return sample_at(t_s, hint);
}

Trajectory::Sample Trajectory::sample_at(double t_s, std::size_t& segment_hint) const {
  // Before the start the first point holds (at exactly the start too, where the velocity is already the first
  // segment's); after the end the last point holds, still.
  if (t_s >= segments_.back().end_s) return {to_vec3(point_on_path(segments_.back(), 1.0)), {0.0, 0.0, 0.0}};
  if (!(t_s >= segments_.front().begin_s)) return {to_vec3(point_on_path(segments_.front(), 0.0)), {0.0, 0.0, 0.0}};
  segment_hint = segment_index_at(t_s, segment_hint);
  const TrajectorySegment& seg = segments_[segment_hint];
  const double tau = segment_tau(seg, t_s);
  const double s = eased_fraction(seg.easing, tau);
  // At the very start the position is the first point exactly, whatever the first segment's easing gives at τ = 0.
  const Vec3 position_m = t_s > segments_.front().begin_s ? to_vec3(point_on_path(seg, s))
                                                          : to_vec3(point_on_path(segments_.front(), 0.0));
  const double span = seg.end_s - seg.begin_s;
  if (span <= 0.0) return {position_m, {0.0, 0.0, 0.0}};
  // dP/dt = dP/ds · ds/dτ · dτ/dt
  return {position_m, to_vec3(path_derivative(seg, s) * (eased_rate(seg.easing, tau) / span))};
}

// ---------------------------------------------------------------------------------------------------------------
// CSV loading

Trajectory load_trajectory_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open trajectory file: " + std::strerror(errno));
  return parse_trajectory_csv(in, path);
}

Trajectory parse_trajectory_csv(std::istream& in, const std::string& path) {
  std::vector<Waypoint> waypoints;
  int previous_line = 0;
  std::string line_text;
  int line_number = 0;
  bool turning = false;  // the header names the orientation columns
  std::size_t columns = 4;
  std::string expected = "expected 4 columns t,x,y,z";
  while (std::getline(in, line_text)) {
    ++line_number;
    std::string_view line = line_text;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);  // files written on Windows

    if (line_number == 1) {
      if (trim(line) == kCsvTurningHeader) {
        turning = true;
        columns = kCsvColumns.size();
        expected = "expected 8 columns t,x,y,z,qw,qx,qy,qz";
        continue;
      }
      if (trim(line) != kCsvHeader) {
        // Point at the first character that differs from the expected header.
        const std::size_t lead = std::min(line.find_first_not_of(" \t"), line.size());
        const std::string_view body = trim(line);
        std::size_t i = 0;
        while (i < body.size() && i < kCsvHeader.size() && body[i] == kCsvHeader[i]) ++i;
        csv_error(path, 1, lead + i + 1, "header", "expected the header 't,x,y,z' (or 't,x,y,z,qw,qx,qy,qz')",
                  line);
      }
      continue;
    }
    if (trim(line).empty()) continue;

    const std::vector<CsvField> fields = split_fields(line);
    if (fields.size() < columns) {
      csv_error(path, line_number, line.size() + 1, kCsvColumns[fields.size()], "missing value: " + expected, line);
    }
    if (fields.size() > columns) {
      csv_error(path, line_number, fields[columns].column, "extra", "too many columns: " + expected,
                fields[columns].text);
    }
    std::array<double, kCsvColumns.size()> values{};
    for (std::size_t c = 0; c < columns; ++c) {
      switch (parse_number(fields[c].text, values[c])) {
        case NumberStatus::ok: break;
        case NumberStatus::not_a_number:
          csv_error(path, line_number, fields[c].column, kCsvColumns[c], "not a number", fields[c].text);
        case NumberStatus::not_finite:
          csv_error(path, line_number, fields[c].column, kCsvColumns[c], "value must be finite", fields[c].text);
      }
    }
    const double t_s = values[0];
    if (t_s < 0.0) {
      csv_error(path, line_number, fields[0].column, "t", "time must be >= 0 (the session starts at t = 0)",
                fields[0].text);
    }
    if (!waypoints.empty() && !(t_s > waypoints.back().t_s)) {
      std::ostringstream reason;
      reason << "time must be strictly increasing (line " << previous_line << " has t = " << waypoints.back().t_s
             << ")";
      csv_error(path, line_number, fields[0].column, "t", reason.str(), fields[0].text);
    }
    Waypoint waypoint{t_s, {values[1], values[2], values[3]}};
    if (turning) {
      waypoint.orientation = Eigen::Quaterniond(values[4], values[5], values[6], values[7]);
      const double norm = waypoint.orientation.norm();
      if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
        std::ostringstream reason;
        reason << "the orientation must be a unit quaternion qw,qx,qy,qz (its norm is " << norm << ")";
        csv_error(path, line_number, fields[4].column, "qw", reason.str(), line.substr(fields[4].column - 1));
      }
    }
    waypoints.push_back(waypoint);
    previous_line = line_number;
  }
  if (line_number == 0) csv_error(path, 1, 1, "header", "empty file: expected the header 't,x,y,z'", "");
  if (waypoints.empty()) csv_error(path, line_number + 1, 1, "t", "no waypoints after the header", "");
  return Trajectory::from_waypoints(waypoints, path, turning);
}

// ---------------------------------------------------------------------------------------------------------------
// Built-ins

namespace {

enum class Range { any, positive, non_negative, nonzero, at_least_one };

const char* range_text(Range range) {
  switch (range) {
    case Range::any: return "";
    case Range::positive: return "must be > 0";
    case Range::non_negative: return "must be >= 0";
    case Range::nonzero: return "must not be 0";
    case Range::at_least_one: return "must be >= 1";
  }
  return "";
}

bool in_range(Range range, double value) {
  switch (range) {
    case Range::any: return true;
    case Range::positive: return value > 0.0;
    case Range::non_negative: return value >= 0.0;
    case Range::nonzero: return value != 0.0;
    case Range::at_least_one: return value >= 1.0;
  }
  return false;
}

// The `key=value,...` part of a spec, checked against the keys the built-in knows.
class BuiltinParams {
 public:
  BuiltinParams(std::string_view name, std::string_view text, std::span<const std::string_view> known_keys)
      : name_(name) {
    if (text.empty()) return;
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t comma = text.find(',', start);
      const std::string_view item =
          trim(text.substr(start, comma == std::string_view::npos ? text.npos : comma - start));
      start = comma == std::string_view::npos ? text.size() + 1 : comma + 1;
      const std::size_t equals = item.find('=');
      if (item.empty()) fail("empty parameter in '" + excerpt(text, 80) + "'");
      if (equals == std::string_view::npos) {
        fail("parameter '" + excerpt(item, 80) + "' has no value (expected key=value)");
      }
      const std::string key(trim(item.substr(0, equals)));
      const std::string value(trim(item.substr(equals + 1)));
      if (std::find(known_keys.begin(), known_keys.end(), key) == known_keys.end()) {
        std::string known;
        for (const std::string_view k : known_keys) known += (known.empty() ? "" : ", ") + std::string(k);
        fail("unknown parameter '" + excerpt(key, 80) + "' (value '" + excerpt(value, 80) + "'); known: " + known);
      }
      if (!values_.emplace(key, value).second) fail("parameter '" + key + "' given twice (value '" + excerpt(value, 80) + "')");
    }
  }

  double number(const std::string& key, double default_value, Range range, std::string_view unit) const {
    const auto it = values_.find(key);
    if (it == values_.end()) return default_value;
    double value = 0.0;
    switch (parse_number(it->second, value)) {
      case NumberStatus::ok: break;
      case NumberStatus::not_a_number: fail(key + "='" + excerpt(it->second, 80) + "': not a number");
      case NumberStatus::not_finite: fail(key + "='" + excerpt(it->second, 80) + "': must be finite");
    }
    if (!in_range(range, value)) {
      fail(key + "='" + excerpt(it->second, 80) + "': " + range_text(range) + (unit.empty() ? "" : " (" + std::string(unit) + ")"));
    }
    return value;
  }

  std::string word(const std::string& key, std::string_view default_value,
                   std::initializer_list<std::string_view> allowed) const {
    const auto it = values_.find(key);
    if (it == values_.end()) return std::string(default_value);
    if (std::find(allowed.begin(), allowed.end(), it->second) == allowed.end()) {
      std::string options;
      for (const std::string_view a : allowed) options += (options.empty() ? "" : ", ") + std::string(a);
      fail(key + "='" + excerpt(it->second, 80) + "': must be one of " + options);
    }
    return it->second;
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const {
    throw TrajectoryError(excerpt(name_, 80) + ": " + reason);
  }

  std::string name_;
  std::map<std::string, std::string, std::less<>> values_;
};

// Appends motions one after another, each starting where and when the previous ended.
class PathBuilder {
 public:
  explicit PathBuilder(const Eigen::Vector3d& start_m) : here_m_(start_m) {}

  void move_to(const Eigen::Vector3d& to_m, Easing easing, double duration_s) {
    if (duration_s <= 0.0) return;
    TrajectorySegment seg;
    seg.easing = easing;
    seg.begin_s = now_s_;
    seg.end_s = now_s_ + duration_s;
    seg.from_m = to_vec3(here_m_);
    seg.to_m = to_vec3(to_m);
    segments_.push_back(seg);
    here_m_ = to_m;
    now_s_ = seg.end_s;
  }

  void hold(double duration_s) { move_to(here_m_, Easing::linear, duration_s); }

  void arc(const Eigen::Vector3d& centre_m, const Eigen::Vector3d& axis_u, const Eigen::Vector3d& axis_v,
           double radius_m, double begin_angle_rad, double end_angle_rad, Easing easing, double duration_s) {
    if (duration_s <= 0.0) return;
    TrajectorySegment seg;
    seg.path = TrajectorySegment::Path::arc;
    seg.easing = easing;
    seg.begin_s = now_s_;
    seg.end_s = now_s_ + duration_s;
    seg.centre_m = to_vec3(centre_m);
    seg.axis_u = to_vec3(axis_u);
    seg.axis_v = to_vec3(axis_v);
    seg.radius_m = radius_m;
    seg.begin_angle_rad = begin_angle_rad;
    seg.end_angle_rad = end_angle_rad;
    segments_.push_back(seg);
    here_m_ = point_on_path(seg, 1.0);
    now_s_ = seg.end_s;
  }

  // From rest at the current point, along `direction` (unit): reach `speed_mps` after half of `standoff_m`, keep it
  // until the contact point `standoff_m` ahead, then slow to rest `depth_m` beyond contact. The cosine ramps keep the
  // velocity continuous; a ramp covering distance d from/to speed v takes 2d/v (mean speed v/2).
  void strike(const Eigen::Vector3d& direction, double standoff_m, double depth_m, double speed_mps) {
    const Eigen::Vector3d start = here_m_;
    const double ramp_m = 0.5 * standoff_m;
    move_to(start + ramp_m * direction, Easing::accelerate, 2.0 * ramp_m / speed_mps);
    move_to(start + standoff_m * direction, Easing::linear, (standoff_m - ramp_m) / speed_mps);
    move_to(start + (standoff_m + depth_m) * direction, Easing::decelerate, 2.0 * depth_m / speed_mps);
  }

  Trajectory build(std::string description) {
    return Trajectory(std::move(segments_), std::move(description));
  }

 private:
  Eigen::Vector3d here_m_;
  double now_s_ = 0.0;
  std::vector<TrajectorySegment> segments_;
};

Trajectory make_tap(const BuiltinParams& p, const std::string& spec) {
  const double speed = p.number("speed", 0.5, Range::positive, "m/s");
  const double depth = p.number("depth", 0.035, Range::positive, "m");
  const double height = p.number("height", 0.025, Range::any, "m");
  const double face_x = p.number("face_x", 0.005, Range::any, "m");
  const double y = p.number("y", 0.0, Range::any, "m");
  const double standoff = p.number("standoff", 0.03, Range::positive, "m");
  const double hold = p.number("hold", 1.5, Range::non_negative, "s");
  const double rest = p.number("rest", 0.0, Range::non_negative, "s");

  const Eigen::Vector3d start(face_x - standoff, y, height);
  PathBuilder path(start);
  if (rest > 0.0) path.hold(rest);  // no segment at all for 0: the default tap is the tap it always was
  path.strike(Eigen::Vector3d::UnitX(), standoff, depth, speed);
  // Withdraw with s = (1 − cos πτ)/2, whose peak speed is π·distance/(2·duration): choose the duration so it is `speed`.
  const double withdraw_m = standoff + depth;
  path.move_to(start, Easing::smooth, kPi * withdraw_m / (2.0 * speed));
  path.hold(hold);
  return path.build(spec);
}

struct PressParams {
  Eigen::Vector3d start_m;
  double standoff_m;
  double depth_m;
};

PressParams press_geometry(const BuiltinParams& p) {
  const double x = p.number("x", 0.0, Range::any, "m");
  const double y = p.number("y", 0.0, Range::any, "m");
  const double surface_z = p.number("surface_z", 0.05, Range::any, "m");
  const double depth = p.number("depth", 0.01, Range::positive, "m");
  const double standoff = p.number("standoff", 0.03, Range::positive, "m");
  return {Eigen::Vector3d(x, y, surface_z + standoff), standoff, depth};
}

Trajectory make_press(const BuiltinParams& p, const std::string& spec) {
  const PressParams press = press_geometry(p);
  const double speed = p.number("speed", 0.1, Range::positive, "m/s");
  const double hold = p.number("hold", 1.0, Range::non_negative, "s");
  PathBuilder path(press.start_m);
  path.strike(-Eigen::Vector3d::UnitZ(), press.standoff_m, press.depth_m, speed);
  path.hold(hold);
  return path.build(spec);
}

Trajectory make_slide(const BuiltinParams& p, const std::string& spec) {
  const PressParams press = press_geometry(p);
  const double press_speed = p.number("press_speed", 0.1, Range::positive, "m/s");
  const double settle = p.number("settle", 0.2, Range::non_negative, "s");
  const double distance = p.number("distance", 0.05, Range::nonzero, "m");
  const double speed = p.number("speed", 0.05, Range::positive, "m/s");
  const double hold = p.number("hold", 0.5, Range::non_negative, "s");

  PathBuilder path(press.start_m);
  path.strike(-Eigen::Vector3d::UnitZ(), press.standoff_m, press.depth_m, press_speed);
  path.hold(settle);
  // Ramps over a quarter of the drag each (2·(d/4)/v), cruise over the middle half (d/2/v).
  const Eigen::Vector3d bottom = press.start_m - (press.standoff_m + press.depth_m) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d drag = distance * Eigen::Vector3d::UnitX();
  const double length = std::abs(distance);
  path.move_to(bottom + 0.25 * drag, Easing::accelerate, 0.5 * length / speed);
  path.move_to(bottom + 0.75 * drag, Easing::linear, 0.5 * length / speed);
  path.move_to(bottom + drag, Easing::decelerate, 0.5 * length / speed);
  path.hold(hold);
  return path.build(spec);
}

Trajectory make_circle(const BuiltinParams& p, const std::string& spec) {
  const double radius = p.number("radius", 0.03, Range::positive, "m");
  const double period = p.number("period", 1.0, Range::positive, "s");
  const Eigen::Vector3d centre(p.number("cx", 0.0, Range::any, "m"), p.number("cy", 0.0, Range::any, "m"),
                               p.number("cz", 0.05, Range::any, "m"));
  const std::string plane = p.word("plane", "xy", {"xy", "xz", "yz"});
  const double turns = p.number("turns", 2.0, Range::at_least_one, "laps");

  const Eigen::Vector3d u = plane == "yz" ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d v = plane == "xy" ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  // A half lap (π) ramped in takes `period`: its end angular speed is 2·π/period, the full-speed rate.
  const double full_sweep = 2.0 * kPi * turns;
  PathBuilder path(centre + radius * u);
  path.arc(centre, u, v, radius, 0.0, kPi, Easing::accelerate, period);
  path.arc(centre, u, v, radius, kPi, full_sweep - kPi, Easing::linear, (turns - 1.0) * period);
  path.arc(centre, u, v, radius, full_sweep - kPi, full_sweep, Easing::decelerate, period);
  return path.build(spec);
}

struct Builtin {
  std::string_view name;
  std::vector<std::string_view> keys;
  Trajectory (*make)(const BuiltinParams&, const std::string&);
};

const std::array<Builtin, 4>& builtins() {
  static const std::array<Builtin, 4> table{{
      {"tap", {"speed", "depth", "height", "face_x", "y", "standoff", "hold", "rest"}, &make_tap},
      {"press", {"x", "y", "surface_z", "depth", "standoff", "speed", "hold"}, &make_press},
      {"slide",
       {"x", "y", "surface_z", "depth", "standoff", "press_speed", "settle", "distance", "speed", "hold"},
       &make_slide},
      {"circle", {"radius", "period", "cx", "cy", "cz", "plane", "turns"}, &make_circle},
  }};
  return table;
}

std::string_view spec_name(std::string_view spec) { return spec.substr(0, spec.find(':')); }

}  // namespace

bool is_builtin_trajectory_name(const std::string& name) {
  const auto& table = builtins();
  return std::any_of(table.begin(), table.end(), [&](const Builtin& b) { return b.name == name; });
}

Trajectory make_builtin_trajectory(const std::string& spec) {
  const std::string_view name = spec_name(spec);
  const std::string_view params = name.size() < spec.size() ? std::string_view(spec).substr(name.size() + 1) : "";
  for (const Builtin& builtin : builtins()) {
    if (builtin.name == name) return builtin.make(BuiltinParams(name, params, builtin.keys), spec);
  }
  std::string known;
  for (const Builtin& builtin : builtins()) known += (known.empty() ? "" : ", ") + std::string(builtin.name);
  throw TrajectoryError("'" + excerpt(name, 80) + "': unknown built-in trajectory; known: " + known);
}

Trajectory load_trajectory(const std::string& spec_or_path) {
  std::error_code ignored;
  if (is_builtin_trajectory_name(std::string(spec_name(spec_or_path))) &&
      !std::filesystem::exists(spec_or_path, ignored)) {
    return make_builtin_trajectory(spec_or_path);
  }
  return load_trajectory_csv(spec_or_path);
}

namespace {

void check_finger_count(std::size_t count, std::size_t max_fingers) {
  if (count == 0 || count > max_fingers) {
    throw TrajectoryError("a device has 1 to " + std::to_string(max_fingers) + " fingers, but " +
                          std::to_string(count) + " were given");
  }
}

void check_new_name(const std::string& name, const std::vector<NamedFinger>& fingers) {
  if (name.empty()) throw TrajectoryError("a finger needs a name");
  for (const NamedFinger& other : fingers) {
    if (other.name == name) throw TrajectoryError("finger '" + name + "' is given twice");
  }
}

}  // namespace

void check_fingers(const std::vector<NamedFinger>& fingers, std::size_t max_fingers) {
  check_finger_count(fingers.size(), max_fingers);
  for (std::size_t k = 0; k < fingers.size(); ++k) {
    check_new_name(fingers[k].name, std::vector<NamedFinger>(fingers.begin(), fingers.begin() + k));
  }
}

std::vector<NamedFinger> parse_fingers(const std::vector<std::string>& specs, std::size_t max_fingers) {
  check_finger_count(specs.size(), max_fingers);
  std::vector<NamedFinger> fingers;
  for (const std::string& spec : specs) {
    const std::size_t equals = spec.find('=');
    if (equals == std::string::npos || equals == 0 || equals + 1 == spec.size()) {
      throw TrajectoryError("finger '" + spec + "': expected NAME=TRAJECTORY (e.g. thumb=grasp_thumb.csv)");
    }
    const std::string name = spec.substr(0, equals);
    check_new_name(name, fingers);
    try {
      Trajectory trajectory = load_trajectory(spec.substr(equals + 1));  // apart from the braced element: see spidar_sim/main.cpp
      fingers.push_back({name, std::move(trajectory)});
    } catch (const TrajectoryError& error) {
      throw TrajectoryError("finger '" + name + "': " + error.what());
    }
  }
  return fingers;
}

}  // namespace impetus
