// SPDX-License-Identifier: Apache-2.0
#pragma once
// Shared set-up for the world_manager tests: ODE is initialised once per process (as the daemon's main does), and
// scenes are built from small JSON documents.

#include "common/link/shm/wire_frames.h"
#include "world_manager/scene.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/world.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

namespace impetus::test {

inline std::unique_ptr<World> make_world(const Scene& scene, const WorldOptions& options = {}) {
  prepare_engines();
  return std::make_unique<World>(scene, options);
}

// Whether the shared-memory transport would deliver `frame` (it validates what it decodes).
inline FrameError transport_verdict(const PlaneFrame& frame) {
  static wire::PlaneFrame encoded;
  static PlaneFrame decoded;
  encode(frame, encoded);
  return decode(encoded, decoded);
}

inline std::string scene_path(const std::string& file) { return std::string(IMPETUS_SOURCE_DIR) + "/scenes/" + file; }

// One free 1 kg-class body and nothing else: no gravity, no floor, so the only velocity change is the impulse.
inline nlohmann::json free_body_document(const nlohmann::json& object) {
  return nlohmann::json{{"gravity_mps2", {0, 0, 0}}, {"floor", nullptr}, {"objects", {object}}};
}

// A report from `session` at `tick` with the finger at `finger_m` (valid) and no impulse entries, counted against
// the world session WorldOptions gives a test world by default.
inline HapticReport make_report(std::uint64_t session, std::uint64_t tick, const Vec3& finger_m = {0, 0, 0},
                                bool finger_valid = false) {
  HapticReport report{};
  report.haptic_session = session;
  report.world_session = WorldOptions{}.world_session;
  report.tick = tick;
  report.finger_m = finger_m;
  report.finger_valid = finger_valid ? 1u : 0u;
  return report;
}

// Every dynamic state double of every object (position, orientation, velocity, angular velocity), for bitwise
// comparisons of runs.
inline std::vector<double> state_bits(const World& world) {
  std::vector<double> record;
  for (const ObjectState& state : world.states()) {
    const auto& p = state.pose.position_m;
    const auto& q = state.pose.orientation.coeffs();
    const auto& v = state.velocity_mps;
    const auto& w = state.angular_velocity_radps;
    for (double x : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w(), v.x(), v.y(), v.z(), w.x(), w.y(), w.z()}) {
      record.push_back(x);
    }
  }
  return record;
}

inline void add_entry(HapticReport& report, std::int32_t object_id, std::uint32_t epoch, const Vec3& impulse_Ns,
                      const Vec3& angular_impulse_Nms = {0, 0, 0}) {
  ObjectImpulse& entry = report.entries[report.entry_count++];
  entry.object_id = object_id;
  entry.epoch = epoch;
  entry.impulse_Ns = impulse_Ns;
  entry.angular_impulse_Nms = angular_impulse_Nms;
  entry.last_tick = report.tick;
}

}  // namespace impetus::test
