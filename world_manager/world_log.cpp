// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world_log.h"

#include "common/runtime/csv_line.h"

#include <algorithm>
#include <cstddef>
#include <sstream>

namespace impetus {
namespace {

// The ring holds whole rows: as many as fit in this much memory, within [2, 64]. 64 rows are 3 s of a 20 Hz world,
// far more than the writer's 2 ms between batches needs; a world of 100 k bodies keeps 2 rows (30 MB).
constexpr std::size_t kRingBytes = 16u << 20;
constexpr std::size_t kMinRows = 2;
constexpr std::size_t kMaxRows = 64;

std::size_t records_per_row(const Scene& scene) {
  const auto logged = static_cast<std::size_t>(std::count_if(
      scene.objects.begin(), scene.objects.end(), [](const SceneObject& o) { return o.dynamic || o.deformable; }));
  return logged + 2;  // the time, the objects (dynamic and deformable), the static reaction
}

std::size_t ring_records(const Scene& scene) {
  const std::size_t per_row = records_per_row(scene);
  const std::size_t rows = std::clamp(kRingBytes / (per_row * sizeof(WorldLogRecord)), kMinRows, kMaxRows);
  return rows * per_row;
}

template <class Vector3>
void put(std::array<double, WorldLogRecord::kObjectColumns>& values, std::size_t at, const Vector3& v) {
  values[at] = v[0];
  values[at + 1] = v[1];
  values[at + 2] = v[2];
}

}  // namespace

WorldLog::WorldLog(const World& world, const std::string& path)
    : world_(world),
      row_(records_per_row(world.scene())),
      log_(path, header(world.scene()), &WorldLog::format, ring_records(world.scene()), LogOverflow::wait,
           "world_manager") {}

std::string WorldLog::header(const Scene& scene) {
  std::ostringstream out;
  out << "time_s";
  for (const SceneObject& object : scene.objects) {
    if (!object.dynamic) continue;
    const std::string& n = object.name;
    out << ',' << n << ".x_m," << n << ".y_m," << n << ".z_m";
    out << ',' << n << ".qw," << n << ".qx," << n << ".qy," << n << ".qz";
    out << ',' << n << ".vx_mps," << n << ".vy_mps," << n << ".vz_mps";
    out << ',' << n << ".wx_radps," << n << ".wy_radps," << n << ".wz_radps";
    out << ',' << n << ".jx_Ns," << n << ".jy_Ns," << n << ".jz_Ns";
    out << ',' << n << ".jx_total_Ns," << n << ".jy_total_Ns," << n << ".jz_total_Ns";
  }
  for (const SceneObject& object : scene.objects) {
    if (!object.deformable) continue;
    const std::string& n = object.name;
    out << ',' << n << ".dent_m," << n << ".dent_volume_m3," << n << ".yielding_Ns";
  }
  out << ",static.jx_total_Ns,static.jy_total_Ns,static.jz_total_Ns";
  out << ",haptic_time_s";
  return out.str();
}

void WorldLog::record() {
  std::size_t next = 0;
  WorldLogRecord& time = row_[next++];
  time.part = WorldLogRecord::Part::time;
  time.values[0] = world_.time_s();
  const auto& objects = world_.scene().objects;
  const auto states = world_.states();
  for (std::size_t id = 0; id < objects.size(); ++id) {
    if (!objects[id].dynamic) continue;
    const ObjectState& state = states[id];
    const Eigen::Quaterniond& q = state.pose.orientation;
    WorldLogRecord& record = row_[next++];
    record.part = WorldLogRecord::Part::object;
    put(record.values, 0, state.pose.position_m);
    record.values[3] = q.w();
    record.values[4] = q.x();
    record.values[5] = q.y();
    record.values[6] = q.z();
    put(record.values, 7, state.velocity_mps);
    put(record.values, 10, state.angular_velocity_radps);
    put(record.values, 13, world_.step_impulse_Ns(id));
    put(record.values, 16, world_.total_impulse_Ns(id));
  }
  for (std::size_t id = 0; id < objects.size(); ++id) {
    const DeformableSurface* surface = world_.deformable(id);
    if (surface == nullptr) continue;
    WorldLogRecord& record = row_[next++];
    record.part = WorldLogRecord::Part::deformable;
    record.values[0] = surface->dent_m();
    record.values[1] = surface->dent_volume_m3();
    record.values[2] = surface->yielding_Ns();
  }
  WorldLogRecord& statics = row_[next++];
  statics.part = WorldLogRecord::Part::statics;
  put(statics.values, 0, world_.total_static_impulse_Ns());
  statics.values[3] = world_.last_report_haptic_time_s();
  // The row goes in whole, so the writer never flushes half a line.
  log_.push_all(row_);
}

void WorldLog::format(std::ostream& out, const WorldLogRecord& record) {
  switch (record.part) {
    case WorldLogRecord::Part::time: {
      CsvLine line(out, CsvLine::Part::first);
      line.number(record.values[0]);
      break;
    }
    case WorldLogRecord::Part::object: {
      CsvLine line(out, CsvLine::Part::middle);
      for (const double value : record.values) line.number(value);
      break;
    }
    case WorldLogRecord::Part::deformable: {
      CsvLine line(out, CsvLine::Part::middle);
      line.number(record.values[0]).number(record.values[1]).number(record.values[2]);
      break;
    }
    case WorldLogRecord::Part::statics: {
      CsvLine line(out, CsvLine::Part::last);
      line.number(record.values[0]).number(record.values[1]).number(record.values[2]).number(record.values[3]);
      break;
    }
  }
}

}  // namespace impetus
