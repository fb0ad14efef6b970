// SPDX-License-Identifier: Apache-2.0
#include "viewer/replay.h"

#include "common/runtime/log_paths.h"
#include "common/runtime/message_text.h"

#include "world_manager/scene.h"
#include "world_manager/world_view.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace impetus::view {
namespace {

namespace fs = std::filesystem;

// A numeric CSV log (header row, then numbers), as every node writes them (docs/architecture.md §4).
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::vector<std::size_t> line_numbers;  // per row: its line in the file (empty lines are skipped)

  int column(const std::string& name) const {
    const auto found = std::find(columns.begin(), columns.end(), name);
    return found == columns.end() ? -1 : static_cast<int>(found - columns.begin());
  }
};

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// How far the world's clock runs ahead of the haptic side's, s: the median over the steps of (the world time a step
// started at) − (the haptic time of the report it applied), the world log's haptic_time_s (scripts/impetus_py/logs.py
// world_clock_offset_s says the same). 0 for a log without that column or before any report.
double world_clock_offset_s(const CsvTable& world, int time_column) {
  const int haptic_column = world.column("haptic_time_s");
  if (haptic_column < 0 || world.rows.size() < 2) return 0.0;
  std::vector<double> steps, offsets;
  for (std::size_t r = 1; r < world.rows.size(); ++r) {
    steps.push_back(world.rows[r][time_column] - world.rows[r - 1][time_column]);
  }
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double period_s = steps[steps.size() / 2];
  for (const std::vector<double>& row : world.rows) {
    const double offset_s = row[time_column] - period_s - row[haptic_column];
    if (std::isfinite(offset_s)) offsets.push_back(offset_s);
  }
  if (offsets.empty()) return 0.0;
  std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
  return offsets[offsets.size() / 2];
}

CsvTable read_csv(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw ReplayError("cannot read " + path.string());
  CsvTable table;
  std::string line;
  if (!std::getline(in, line)) throw ReplayError(path.string() + ": empty (no header row)");
  table.columns = split(line);
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const std::vector<std::string> fields = split(line);
    if (fields.size() != table.columns.size()) {
      throw ReplayError(path.string() + ":" + std::to_string(number) + ": " + std::to_string(fields.size()) +
                        " fields, the header has " + std::to_string(table.columns.size()) +
                        " (a log cut short by a crash ends in a partial row: delete that row)");
    }
    std::vector<double> row(fields.size());
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::string& text = fields[c];
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), row[c]);
      if (error != std::errc() || end != text.data() + text.size()) {
        throw ReplayError(path.string() + ":" + std::to_string(number) + ": column " + std::to_string(c + 1) + " ('" +
                          excerpt(table.columns[c], 40) + "') is not a number: '" + excerpt(text, 40) + "'");
      }
    }
    table.rows.push_back(std::move(row));
    table.line_numbers.push_back(number);
  }
  return table;
}

// A log's clock must be finite and never run backwards: a replay seeks in it by time.
void check_times(const CsvTable& table, int column, const fs::path& path) {
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const double time_s = table.rows[r][static_cast<std::size_t>(column)];
    const std::string where = path.string() + ":" + std::to_string(table.line_numbers[r]) + ": " +
                              table.columns[static_cast<std::size_t>(column)];
    if (!std::isfinite(time_s)) throw ReplayError(where + " is not a finite time");
    if (r > 0 && time_s < table.rows[r - 1][static_cast<std::size_t>(column)]) {
      throw ReplayError(where + " " + std::to_string(time_s) + " is before the row above's (a log's time never " +
                        "runs backwards)");
    }
  }
}

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw ReplayError("cannot read " + path.string() + " (is this a trial folder written by scripts/run.sh?)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {
    throw ReplayError(path.string() + ": " + error.what());
  }
}

// The scene a summary names: as written (absolute, or relative to where the viewer runs), else relative to the trial
// folder, its parent or the source tree (trials are usually started from the source tree).
fs::path find_scene(const std::string& named, const fs::path& dir) {
  const fs::path path(named);
  const fs::path candidates[] = {path, dir / path, dir.parent_path() / path, fs::path(IMPETUS_SOURCE_DIR) / path};
  for (const fs::path& candidate : candidates) {
    std::error_code error;
    if (fs::is_regular_file(candidate, error)) return candidate;
  }
  throw ReplayError((dir / "summary.json").string() + ": /config/scene: no such file '" + named + "'");
}

// The row of a log sorted by `time_column` that is the last at or before `time_s` (from `next`, which advances), and
// whether there is one (else row 0, before the log starts).
bool advance_to(const CsvTable& table, int time_column, double time_s, std::size_t& next) {
  while (next + 1 < table.rows.size() && table.rows[next + 1][time_column] <= time_s) ++next;
  return table.rows[next][time_column] <= time_s;
}

// A tool's pose log (haptic.tool.csv, haptic_controller/haptic_node.h ToolLogRow): its poses and wrench at each frame
// time (on the world's clock, `world_ahead_s` ahead of the haptic side's).
std::vector<ViewToolFrame> read_tool_track(const fs::path& path, const std::vector<double>& times_s,
                                           double world_ahead_s) {
  const CsvTable log = read_csv(path);
  static const char* const kColumns[] = {"time_s",    "grip_x_m",  "grip_y_m",  "grip_z_m",  "grip_qw",   "grip_qx",
                                         "grip_qy",   "grip_qz",   "proxy_x_m", "proxy_y_m", "proxy_z_m", "proxy_qw",
                                         "proxy_qx",  "proxy_qy",  "proxy_qz",  "force_x_N", "force_y_N", "force_z_N",
                                         "torque_x_Nm", "torque_y_Nm", "torque_z_Nm", "flags"};
  constexpr std::size_t kCount = std::size(kColumns);
  std::array<int, kCount> c{};
  for (std::size_t v = 0; v < kCount; ++v) {
    c[v] = log.column(kColumns[v]);
    if (c[v] < 0) throw ReplayError(path.string() + ": no column '" + kColumns[v] + "'");
  }
  std::vector<ViewToolFrame> frames(times_s.size());
  if (log.rows.empty()) return frames;
  check_times(log, c[0], path);
  const auto posed = [&](std::size_t r) { return (static_cast<std::uint32_t>(log.rows[r][c[21]]) & 1u) != 0; };
  // Past the log's end the tool rests where it was last posed: the servo's last ticks may come after the device's
  // session ended, with no pose, while the world logs one more step.
  std::size_t last_posed = log.rows.size() - 1;
  while (last_posed > 0 && !posed(last_posed)) --last_posed;
  std::size_t next = 0;
  for (std::size_t f = 0; f < times_s.size(); ++f) {
    const bool started = advance_to(log, c[0], times_s[f] - world_ahead_s, next);
    const bool ended = next + 1 == log.rows.size() && times_s[f] - world_ahead_s > log.rows[next][c[0]];
    const std::vector<double>& row = log.rows[ended ? last_posed : next];
    ViewToolFrame& frame = frames[f];
    auto value = [&](std::size_t v) { return row[static_cast<std::size_t>(c[v])]; };
    for (int i = 0; i < 3; ++i) {
      frame.grip.position_m[i] = value(1 + i);
      frame.proxy.position_m[i] = value(8 + i);
      frame.force_N[i] = value(15 + i);
      frame.torque_Nm[i] = value(18 + i);
    }
    for (int i = 0; i < 4; ++i) {
      frame.grip.orientation_wxyz[i] = value(4 + i);
      frame.proxy.orientation_wxyz[i] = value(11 + i);
    }
    const auto unit = [](const std::array<double, 4>& q) {
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      return std::abs(norm - 1.0) < 1e-6;
    };
    // A tick without a pose (flags bit 0 clear) logs the last pose it had; a grip before its first tick has none.
    const bool grip_valid = posed(ended ? last_posed : next);
    frame.valid = started && grip_valid && all_finite(frame.grip.position_m) && all_finite(frame.proxy.position_m) &&
                  all_finite(frame.force_N) && all_finite(frame.torque_Nm) && unit(frame.grip.orientation_wxyz) &&
                  unit(frame.proxy.orientation_wxyz);
    if (!frame.valid) frame = ViewToolFrame{};
  }
  return frames;
}

Coupling coupling_named(const std::string& name, const fs::path& summary) {
  for (Coupling coupling : {Coupling::impulse, Coupling::position, Coupling::local}) {
    if (name == to_string(coupling)) return coupling;
  }
  throw ReplayError(summary.string() + ": /config/coupling: unknown coupling '" + name + "'");
}

}  // namespace

Replay::Replay(const std::string& dir) : dir_(dir), scene_(std::make_unique<ViewScene>()) {
  const fs::path folder(dir);
  const fs::path summary_path = folder / "summary.json";
  const nlohmann::json summary = read_json(summary_path);
  const nlohmann::json config = summary.value("config", nlohmann::json::object());
  if (!config.contains("scene") || !config["scene"].is_string()) {
    throw ReplayError(summary_path.string() + ": /config/scene: missing (not a trial summary?)");
  }
  Scene scene;
  try {
    scene = load_scene(find_scene(config["scene"].get<std::string>(), folder).string());
  } catch (const SceneError& error) {
    throw ReplayError(error.what());
  }
  const std::string coupling = config.value("coupling", std::string("impulse"));
  const double rate_hz = config.contains("world_rate_hz") && config["world_rate_hz"].is_number()
                             ? config["world_rate_hz"].get<double>()
                             : scene.physics.world_rate_hz;
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw ReplayError(summary_path.string() + ": /config/world_rate_hz: not a positive rate");
  }
  world_period_s_ = 1.0 / rate_hz;
  describe_scene(scene, coupling_named(coupling, summary_path), rate_hz, 0, *scene_);

  // Poses: dynamic bodies from world.csv, static ones where the scene puts them.
  const fs::path world_path = folder / "world.csv";
  const CsvTable world = read_csv(world_path);
  if (world.rows.empty()) throw ReplayError(world_path.string() + ": no steps were logged");
  const int time_column = world.column("time_s");
  if (time_column < 0) throw ReplayError(world_path.string() + ": no time_s column");
  check_times(world, time_column, world_path);
  const std::size_t bodies = scene_->body_count;
  std::vector<std::array<int, 7>> columns(bodies);
  static const char* const kSuffix[7] = {".x_m", ".y_m", ".z_m", ".qw", ".qx", ".qy", ".qz"};
  for (std::size_t k = 0; k < bodies; ++k) {
    for (int v = 0; v < 7; ++v) {
      columns[k][v] = scene.objects[k].dynamic ? world.column(scene.objects[k].name + kSuffix[v]) : -1;
      if (scene.objects[k].dynamic && columns[k][v] < 0) {
        throw ReplayError(world_path.string() + ": no column '" + scene.objects[k].name + kSuffix[v] +
                          "' (was the trial run with another scene?)");
      }
    }
  }
  times_s_.reserve(world.rows.size());
  poses_.reserve(world.rows.size() * bodies);
  for (const std::vector<double>& row : world.rows) {
    times_s_.push_back(row[time_column]);
    for (std::size_t k = 0; k < bodies; ++k) {
      if (columns[k][0] < 0) {
        poses_.push_back(scene_pose(scene.objects[k]));
        continue;
      }
      ViewBodyPose pose;
      for (int v = 0; v < 3; ++v) pose.position_m[v] = row[columns[k][v]];
      for (int v = 0; v < 4; ++v) pose.orientation_wxyz[v] = row[columns[k][3 + v]];
      poses_.push_back(pose);
    }
  }

  // Each endpoint's finger at each step's time: the last row at or before it of its haptic log (haptic.csv, then
  // haptic.endpoint1.csv, ... for a device of several fingers), on the haptic side's clock.
  const double world_ahead_s = world_clock_offset_s(world, time_column);
  for (std::uint32_t e = 0; e < kMaxViewEndpoints; ++e) {
    const fs::path haptic_path = folder / (e == 0 ? std::string("haptic.csv") : "haptic.endpoint" + std::to_string(e) + ".csv");
    std::error_code missing;
    if (!fs::is_regular_file(haptic_path, missing)) break;
    const CsvTable haptic = read_csv(haptic_path);
    static const char* const kHapticColumns[] = {"time_s",    "finger_x_m", "finger_y_m", "finger_z_m",
                                                 "proxy_x_m", "proxy_y_m",  "proxy_z_m",  "force_x_N",
                                                 "force_y_N", "force_z_N"};
    std::array<int, 10> hc{};
    for (int v = 0; v < 10; ++v) {
      hc[v] = haptic.column(kHapticColumns[v]);
      // Logs recorded before the columns carried their units name them without it ("force_x"): still replayed.
      if (hc[v] < 0) {
        const std::string name = kHapticColumns[v];
        hc[v] = haptic.column(name.substr(0, name.rfind('_')));
      }
      if (hc[v] < 0) throw ReplayError(haptic_path.string() + ": no column '" + kHapticColumns[v] + "'");
    }
    if (haptic.rows.empty()) break;
    check_times(haptic, hc[0], haptic_path);
    std::vector<ViewEndpoint>& track = endpoints_.emplace_back(times_s_.size());
    std::size_t next = 0;
    for (std::size_t f = 0; f < times_s_.size(); ++f) {
      // Before the finger's first tick (a world started before the finger) there is no finger yet.
      const bool started = advance_to(haptic, hc[0], times_s_[f] - world_ahead_s, next);
      const std::vector<double>& row = haptic.rows[next];
      ViewEndpoint& endpoint = track[f];
      endpoint.endpoint = e;
      endpoint.finger_m = {row[hc[1]], row[hc[2]], row[hc[3]]};
      endpoint.proxy_m = {row[hc[4]], row[hc[5]], row[hc[6]]};
      endpoint.force_N = {row[hc[7]], row[hc[8]], row[hc[9]]};
      endpoint.finger_valid =
          all_finite(endpoint.finger_m) && all_finite(endpoint.proxy_m) && all_finite(endpoint.force_N);
      if (!endpoint.finger_valid || !started) endpoint = ViewEndpoint{};
    }
  }

  // A tool in the hand: drawn where its pose log puts it (a trial without that log shows its grip as a finger's).
  const fs::path tool_path = folder / tool_log_path("haptic.csv");
  std::error_code missing;
  if (scene.tool && fs::is_regular_file(tool_path, missing)) {
    tool_ = scene.tool->shape;
    tool_frames_ = read_tool_track(tool_path, times_s_, world_ahead_s);
  }
}

std::size_t Replay::frame_at(double time_s) const {
  const auto after = std::upper_bound(times_s_.begin(), times_s_.end(), time_s);
  return after == times_s_.begin() ? 0 : static_cast<std::size_t>(after - times_s_.begin()) - 1;
}

void Replay::snapshot(std::size_t frame, WorldSnapshot& out) const {
  out.world_session = 0;
  out.frame_index = frame;
  out.world_time_s = times_s_[frame];
  out.world_period_s = world_period_s_;
  out.world_stats = LoopStats{};
  out.haptic_stats = LoopStats{};
  out.body_count = scene_->body_count;
  std::copy_n(poses_.begin() + static_cast<std::ptrdiff_t>(frame * out.body_count), out.body_count, out.bodies.begin());
  out.endpoint_count = static_cast<std::uint32_t>(endpoints_.size());
  for (std::size_t e = 0; e < endpoints_.size(); ++e) out.endpoints[e] = endpoints_[e][frame];
}

}  // namespace impetus::view
