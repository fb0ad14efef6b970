// SPDX-License-Identifier: Apache-2.0
#include "world_manager/world_node.h"

#include "common/runtime/lockstep.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/process.h"
#include "common/runtime/realtime_clock.h"
#include "common/runtime/staleness.h"
#include "common/spidar/geometry.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/impulse_limits.h"
#include "world_manager/world_view.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace impetus {
namespace {

Scene scene_with_overrides(const WorldNodeOptions& options) {
  Scene scene = options.scene_text.empty() ? load_scene(options.scene_path)
                                            : parse_scene_text(options.scene_text, options.scene_path);
  if (options.substeps) scene.physics.substeps = *options.substeps;
  if (options.engine) {
    if (find_engine(*options.engine) == nullptr) {
      throw std::invalid_argument("engine: unknown engine '" + *options.engine + "', expected " + engine_names());
    }
    scene.physics.engine = *options.engine;
  }
  return scene;
}

WorldOptions world_options(const WorldNodeOptions& options) {
  WorldOptions world;
  world.coupling = options.coupling;
  world.passivity = options.passivity;
  world.world_rate_hz = options.rate_hz;
  world.world_session = options.world_session != 0 ? options.world_session : new_session_id();
  return world;
}

nlohmann::json to_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

WorldNode::WorldNode(const WorldNodeOptions& options)
    : options_(options),
      scene_(scene_with_overrides(options)),
      world_(scene_, world_options(options)),
      reports_(kMaxEndpoints) {
  if (options.clock == ClockMode::lockstep) {
    const std::uint64_t ticks = LockstepSchedule::ticks_per_world_step(world_.world_period_s(), options.haptic_rate_hz);
    // Step i happens at tick i·n + phase: a phase of n or more only delays every step by whole periods, and a trial
    // shorter than the delay would run with no world at all.
    if (options.phase_ticks >= ticks) {
      char message[256];
      std::snprintf(message, sizeof message,
                    "--phase %llu is not within one world period: a %g Hz world at a %g Hz haptic rate steps every "
                    "%llu ticks, so the phase must be 0 to %llu",
                    static_cast<unsigned long long>(options.phase_ticks), 1.0 / world_.world_period_s(),
                    options.haptic_rate_hz, static_cast<unsigned long long>(ticks),
                    static_cast<unsigned long long>(ticks - 1));
      throw std::invalid_argument(message);
    }
  }
  if (!options.log_path.empty()) log_.emplace(world_, options.log_path);
}

WorldLinkInfo WorldNode::link_info() const {
  WorldLinkInfo info;
  info.world_rate_hz = 1.0 / world_.world_period_s();
  info.world_period_s = world_.world_period_s();
  info.phase_ticks = options_.phase_ticks;
  info.clock = options_.clock;
  info.coupling = options_.coupling;
  return info;
}

std::vector<std::string> WorldNode::warnings() const {
  std::vector<std::string> out;
  char text[512];
  if (options_.coupling == Coupling::impulse) {
    const double max_force_N = SpidarGeometry{}.max_force_N;
    const LightObjects light = light_for_impulse_coupling(scene_, world_.world_period_s(), max_force_N);
    if (light.count > 0) {
      std::snprintf(text, sizeof text,
                    "%zu object(s) are light for impulse coupling at %.1f Hz, the lightest '%s' (%.3g kg): the "
                    "device's %.0f N held for one world period would give it %.3g m/s; a push can launch it. Use "
                    "--coupling local or a faster --rate.",
                    light.count, 1.0 / world_.world_period_s(), light.lightest_name.c_str(), light.lightest_mass_kg,
                    max_force_N, light.lightest_speed_mps);
      out.emplace_back(text);
    }
  }
  if (scene_.physics.engine != "ode") {
    for (const SceneObject& object : scene_.objects) {
      if (!object.smooth_surface) continue;
      std::snprintf(text, sizeof text,
                    "'%s' has a smooth surface, but the %s engine collides its triangles (only ode touches the floor "
                    "with the smooth surface): it rolls as a polygon does",
                    object.name.c_str(), scene_.physics.engine.c_str());
      out.emplace_back(text);
    }
  }
  const std::size_t floor_id = scene_.objects.size();
  for (const RigidBodyEngine::Overlap& overlap : world_.start_overlaps()) {
    const std::string other = overlap.b == floor_id ? "the floor" : "'" + scene_.objects[overlap.b].name + "'";
    std::snprintf(text, sizeof text,
                  "'%s' starts %.3g mm inside %s (the engine will push them apart on the first steps); place them "
                  "apart in the scene",
                  scene_.objects[overlap.a].name.c_str(), overlap.depth_m * 1e3, other.c_str());
    out.emplace_back(text);
  }
  return out;
}

void WorldNode::connect_view(WorldViewPublisher& view) {
  view_ = &view;
  auto scene = std::make_unique<ViewScene>();
  describe_scene(world_.scene(), world_.coupling(), 1.0 / world_.world_period_s(), world_.frame().world_session,
                 *scene);
  view_->publish_scene(*scene);
  snapshot_ = std::make_unique<WorldSnapshot>();
}

void WorldNode::step_world() {
  const std::int64_t now_ns = monotonic_now_ns();
  const std::uint32_t slots = std::min(link_->endpoint_slots(), kMaxEndpoints);
  // Slots past the last one that ever reported carry nothing: the world serves up to the last used slot.
  std::uint32_t used = 0;
  for (std::uint32_t slot = 0; slot < slots; ++slot) {
    SlotReport& slot_report = reports_[slot];
    HapticReport& incoming = incoming_;
    if (link_->latest_report(slot, incoming)) {
      if (!slot_report.have || incoming.haptic_session != slot_report.session || incoming.tick != slot_report.tick) {
        slot_report.fresh_ns = now_ns;
        slot_report.session = incoming.haptic_session;
        slot_report.tick = incoming.tick;
      }
      slot_report.report = incoming;
      slot_report.have = true;
    }
    // An endpoint that stopped reporting (killed, stalled) no longer knows where the finger is: drop its finger so
    // position coupling stops pushing with a stale sample. Its impulse totals stay as they were, so the ledger
    // applies nothing more from them; a restarted controller starts a new session from zero.
    if (options_.clock == ClockMode::realtime && slot_report.have &&
        static_cast<double>(now_ns - slot_report.fresh_ns) * 1e-9 > endpoint_stale_s(world_.world_period_s())) {
      if (slot_report.report.finger_valid != 0) ++stale_finger_steps_;
      slot_report.report.finger_valid = 0;
    }
    report_of_slot_[slot] = slot_report.have ? &slot_report.report : nullptr;
    if (slot_report.have) used = slot + 1;
  }
  // Slot 0 is always served, so a world with no haptic side yet still steps and publishes its first frames.
  used = std::max(used, 1u);
  const std::int64_t cpu_before_ns = thread_cpu_now_ns();
  const std::span<const PlaneFrame> frames =
      world_.step(std::span<const HapticReport* const>(report_of_slot_.data(), used));
  step_cpu_ns_.record(thread_cpu_now_ns() - cpu_before_ns);
  for (std::uint32_t slot = 0; slot < used && slot < slots; ++slot) link_->publish_frame(slot, frames[slot]);
  if (view_ != nullptr) {
    LoopStats haptic_stats;
    const bool have_haptic_stats = link_->latest_haptic_stats(0, haptic_stats);
    take_snapshot(world_, std::span<const HapticReport* const>(report_of_slot_.data(), used), stats_,
                  have_haptic_stats ? &haptic_stats : nullptr, *snapshot_);
    view_->publish_snapshot(*snapshot_);
  }
  // Rare and never on the haptic path: the world loop can afford a line on stderr when it happens.
  for (; escapes_reported_ < world_.escaped().size(); ++escapes_reported_) {
    const std::size_t id = world_.escaped()[escapes_reported_];
    std::fprintf(stderr, "world_manager: warning: at %.3f s the solver threw '%s' out of range (beyond %g m or not "
                 "finite); it is taken out of the simulation\n", world_.time_s(), scene_.objects[id].name.c_str(),
                 kEscapeDistance_m);
  }
  if (log_) log_->record();
}

void WorldNode::publish_stats(const RealtimeClock* clock) {
  stats_ = loop_stats_now(clock);
  stats_.ticks = world_.steps_taken();
  stats_.rejected_frames = link_->rejected_reports();
  link_->publish_stats(stats_);
}

int WorldNode::run() {
  if (link_ == nullptr) throw std::logic_error("WorldNode::run without a link");
  const std::uint64_t max_steps =
      options_.duration_s > 0.0
          ? static_cast<std::uint64_t>(std::llround(options_.duration_s / world_.world_period_s()))
          : std::numeric_limits<std::uint64_t>::max();
  bool cut_short = false;  // the lockstep master died mid-trial: the trial is incomplete
  if (options_.clock == ClockMode::lockstep) {
    // Between its turns this thread writes the log's rows (a world step's row, object by object).
    const LockstepIdleWork idle(
        [](void* node) {
          auto& log = static_cast<WorldNode*>(node)->log_;
          return log && log->drain_one();
        },
        this);
    while (world_.steps_taken() < max_steps) {
      const TurnResult result = link_->wait_turn();
      if (result != TurnResult::ok) {
        if (result == TurnResult::corrupted) {
          std::fprintf(stderr, "world_manager: error: %s; the trial is incomplete\n", to_string(result));
          cut_short = true;
        } else if (result == TurnResult::peer_gone && !g_stop_requested.load()) {
          std::fprintf(stderr, "world_manager: error: the haptic controller went away mid-trial (lockstep); the trial "
                               "is incomplete\n");
          cut_short = true;
        }
        break;
      }
      step_world();
      publish_stats(nullptr);
      link_->finish_turn();
      if (g_stop_requested.load()) break;  // turns keep coming while the master runs: stop between them
    }
    publish_stats(nullptr);
  } else {
    RealtimeClock clock(world_.world_period_s());
    while (!g_stop_requested.load() && world_.steps_taken() < max_steps) {
      world_.note_skipped_steps(clock.wait_next().skipped);
      step_world();
      publish_stats(&clock);
    }
  }
  if (log_) log_->close();
  return cut_short || (log_ && log_->failed()) ? 1 : 0;  // each reported when it happened
}

nlohmann::json WorldNode::escaped_names() const {
  nlohmann::json names = nlohmann::json::array();
  for (std::size_t id : world_.escaped()) names.push_back(scene_.objects[id].name);
  return names;
}

std::size_t WorldNode::asleep_count() const {
  std::size_t asleep = 0;
  for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
    if (scene_.objects[id].dynamic && world_.asleep(id)) ++asleep;
  }
  return asleep;
}

nlohmann::json WorldNode::summary() const {
  nlohmann::json objects = nlohmann::json::object();
  const auto states = world_.states();
  for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
    const auto& object = scene_.objects[id];
    if (!object.dynamic) continue;
    const ObjectState& state = states[id];
    const Eigen::Quaterniond& q = state.pose.orientation;
    const Eigen::Vector3d inertia_kgm2 = impetus::inertia_kgm2(object.shape, object.mass_kg).diagonal();  // principal
    objects[object.name] = {{"mass_kg", object.mass_kg},
                            {"inertia_kgm2", to_json(inertia_kgm2)},
                            {"position", to_json(state.pose.position_m)},
                            {"orientation", {q.w(), q.x(), q.y(), q.z()}},
                            {"velocity", to_json(state.velocity_mps)},
                            {"angular_velocity", to_json(state.angular_velocity_radps)},
                            {"impulse_Ns", to_json(world_.total_impulse_Ns(id))},
                            {"angular_impulse_Nms", to_json(world_.total_angular_impulse_Nms(id))}};
  }
  // Per endpoint of each haptic session: the impulse applied from its reports, by object id (as the haptic summary
  // lists what each endpoint rendered), dynamic objects only.
  nlohmann::json endpoints = nlohmann::json::array();
  for (const CounterOwner& owner : world_.impulse_owners()) {
    nlohmann::json impulses = nlohmann::json::object();
    for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
      if (scene_.objects[id].dynamic) impulses[std::to_string(id)] = to_json(world_.applied_by(owner, id));
    }
    endpoints.push_back({{"haptic_session", owner.haptic_session}, {"endpoint", owner.endpoint},
                         {"impulse_by_object_Ns", impulses}});
  }
  // The impulse port's energy books (couplings/passivity_layer.h), per dynamic object that was pushed and summed.
  auto port_json = [](const PortEnergy& books) {
    return nlohmann::json{{"hand_input_J", books.hand_input_J},
                          {"port_work_J", books.port_work_J},
                          {"overdraft_J", books.overdraft_J()},
                          {"withheld_J", books.withheld_J},
                          {"damped_J", books.damped_J},
                          {"unrecovered_J", books.unrecovered_J},
                          {"returned_J", books.returned_J},
                          {"removed_impulse_Ns", books.removed_impulse_Ns},
                          {"interventions", books.interventions}};
  };
  nlohmann::json port_objects = nlohmann::json::object();
  for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
    const PortEnergy& books = world_.port().energy(id);
    if (books.hand_input_J != 0.0 || books.port_work_J != 0.0 || books.interventions != 0) {
      port_objects[scene_.objects[id].name] = port_json(books);
    }
  }
  // Each deformable object's dent (deform/deformable_surface.h) and the push it absorbed.
  nlohmann::json deformable = nlohmann::json::object();
  for (std::size_t id = 0; id < scene_.objects.size(); ++id) {
    const DeformableSurface* surface = world_.deformable(id);
    if (surface == nullptr) continue;
    deformable[scene_.objects[id].name] = {{"rule", to_string(surface->material().rule)},
                                           {"max_dent_m", surface->max_dent_m()},
                                           {"dent_volume_m3", surface->dent_volume_m3()},
                                           {"absorbed_Ns", surface->absorbed_Ns()},
                                           {"yielding_Ns", surface->yielding_Ns()},
                                           {"lost_Ns", surface->lost_Ns()},
                                           {"clamped_m3", surface->clamped_m3()}};
    nlohmann::json& entry = deformable[scene_.objects[id].name];
    entry["law"] = to_string(surface->material().law);
    if (surface->material().law == DeformableMaterial::Law::elastic) {
      // The elastic law's books (deform/elastic_membrane.h): the surface springs back, so its depth now, the
      // pushes' work, and where the work went.
      entry["dent_m"] = surface->dent_m();
      entry["compliance_mpN"] = surface->compliance_mpN();
      entry["work_J"] = surface->work_J();
      entry["dissipated_J"] = surface->dissipated_J();
      entry["stored_J"] = surface->stored_J();
      entry["scheme_J"] = surface->scheme_J();
      entry["given_back_J"] = surface->given_back_J();
    }
    const DeformableSurface::Profile row = surface->deepest_row();
    entry["deepest_row"] = {
        {"y_m", row.y_m}, {"x0_m", row.x0_m}, {"dx_m", row.dx_m}, {"depth_m", row.depth_m}};
  }
  nlohmann::json port = port_json(world_.port().total());
  port["layer"] = world_.port().enabled();
  port["objects"] = port_objects;
  return {{"objects", objects},
          {"world",
           {{"steps", world_.steps_taken()},
            {"port", port},
            {"deformable", deformable},
            {"endpoints", endpoints},
            {"time_s", world_.time_s()},
            {"period_s", world_.world_period_s()},
            {"skipped_periods", stats_.skipped_periods},
            {"rejected_reports", stats_.rejected_frames},
            {"channel_repairs", link_ != nullptr ? link_->channel_repairs() : 0},
            {"foreign_reports", world_.foreign_reports()},
            {"clipped_reports", world_.clipped_reports()},
            {"warnings", warnings()},
            {"clipped_impulse_Ns", world_.clipped_impulse_Ns()},
            {"stale_finger_steps", stale_finger_steps_},
            {"escaped_objects", escaped_names()},
            {"floor_penetration_max_m", world_.floor_penetration_max_m()},
            {"asleep_objects", asleep_count()},
            {"simulated_objects_per_step_mean",
             world_.steps_taken() > 0 ? static_cast<double>(world_.simulated_object_steps()) /
                                            static_cast<double>(world_.steps_taken())
                                      : 0.0},
            {"lateness_p50_ns", stats_.lateness_p50_ns},
            {"lateness_p99_ns", stats_.lateness_p99_ns},
            {"lateness_max_ns", stats_.lateness_max_ns},
            {"static_impulse_Ns", to_json(world_.total_static_impulse_Ns())},
            {"mechanical_energy_J", world_.mechanical_energy_J()},
            {"cpu_per_step_p50_us", step_cpu_ns_.percentile_ns(0.5) / 1e3},
            {"cpu_per_step_p99_us", step_cpu_ns_.percentile_ns(0.99) / 1e3},
            {"cpu_per_step_mean_us", step_cpu_ns_.mean_ns() / 1e3},
            {"cpu_per_simulated_s", step_cpu_ns_.mean_ns() * 1e-9 / world_.world_period_s()}}},
          {"config",
           {{"scene", options_.scene_path},
            {"world_rate_hz", 1.0 / world_.world_period_s()},
            {"coupling", to_string(world_.coupling())},
            {"passivity", world_.port().enabled()},
            {"clock", to_string(options_.clock)},
            {"phase_ticks", options_.phase_ticks},
            {"substeps", scene_.physics.substeps},
            {"gravity_mps2", {scene_.gravity_mps2[0], scene_.gravity_mps2[1], scene_.gravity_mps2[2]}},
            {"engine", scene_.physics.engine},
            {"solver_iterations", scene_.physics.ode.solver_iterations}}}};
}

}  // namespace impetus
