#include "world_manager/world_log.h"

#include <array>
#include <cstdio>
#include <string>

namespace impetus {

namespace {

// 17 significant digits round-trip a double exactly, so a log can reproduce a run's state bit for bit.
constexpr int kDigits = 17;

void write_number(std::ostream& out, double value) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.*g", kDigits, value);
  out << ',' << text.data();
}

void write_vector(std::ostream& out, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) write_number(out, v[i]);
}

}  // namespace

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
  std::array<char, 32> time{};
  std::snprintf(time.data(), time.size(), "%.*g", kDigits, world_.time_s());
  out << time.data();
  const auto& objects = world_.scene().objects;
  const auto states = world_.states();
  for (std::size_t id = 0; id < objects.size(); ++id) {
    if (!objects[id].dynamic) continue;
    const ObjectState& state = states[id];
    write_vector(out, state.pose.position_m);
    const Eigen::Quaterniond& q = state.pose.orientation;
    write_number(out, q.w());
    write_number(out, q.x());
    write_number(out, q.y());
    write_number(out, q.z());
    write_vector(out, state.velocity_mps);
    write_vector(out, state.angular_velocity_radps);
    write_vector(out, world_.step_impulse_Ns(id));
    write_vector(out, world_.total_impulse_Ns(id));
  }
  write_vector(out, world_.total_static_impulse_Ns());
  out << '\n';
}

}  // namespace impetus
