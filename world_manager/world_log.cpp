// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world_log.h"

#include "common/runtime/csv_line.h"

#include <string>

namespace impetus {

void WorldLog::write_header(std::ostream& out) const {
  out << "time_s";
  const auto& objects = world_.scene().objects;
  for (const SceneObject& object : objects) {
    if (!object.dynamic) continue;
    const std::string& n = object.name;
    out << ',' << n << ".x_m," << n << ".y_m," << n << ".z_m";
    out << ',' << n << ".qw," << n << ".qx," << n << ".qy," << n << ".qz";
    out << ',' << n << ".vx_mps," << n << ".vy_mps," << n << ".vz_mps";
    out << ',' << n << ".wx_radps," << n << ".wy_radps," << n << ".wz_radps";
    out << ',' << n << ".jx_Ns," << n << ".jy_Ns," << n << ".jz_Ns";
    out << ',' << n << ".jx_total_Ns," << n << ".jy_total_Ns," << n << ".jz_total_Ns";
  }
  out << ",static.jx_total_Ns,static.jy_total_Ns,static.jz_total_Ns\n";
}

void WorldLog::write_row(std::ostream& out) const {
  CsvLine line(out);
  line.number(world_.time_s());
  const auto& objects = world_.scene().objects;
  const auto states = world_.states();
  for (std::size_t id = 0; id < objects.size(); ++id) {
    if (!objects[id].dynamic) continue;
    const ObjectState& state = states[id];
    const Eigen::Quaterniond& q = state.pose.orientation;
    line.vector(state.pose.position_m).number(q.w()).number(q.x()).number(q.y()).number(q.z());
    line.vector(state.velocity_mps).vector(state.angular_velocity_radps);
    line.vector(world_.step_impulse_Ns(id)).vector(world_.total_impulse_Ns(id));
  }
  line.vector(world_.total_static_impulse_Ns());
}

}  // namespace impetus
