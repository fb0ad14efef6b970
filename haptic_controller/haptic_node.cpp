// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/haptic_node.h"

#include "common/runtime/lockstep.h"
#include "common/runtime/csv_line.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/runtime/process.h"
#include "common/runtime/realtime_clock.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

namespace impetus {
namespace {

// Rows of the log ring: 2 s at 1 kHz, far more than the drain thread's 2 ms sleep needs.
constexpr std::size_t kLogRows = 2048;
// Loop statistics are published every this many ticks (10 Hz at 1 kHz: a heartbeat, not a trace).
constexpr std::uint64_t kStatsEveryTicks = 100;

constexpr const char* kLogHeader =
    "time_s,tick,finger_x_m,finger_y_m,finger_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N,"
    "object_impulse_x_Ns,object_impulse_y_Ns,object_impulse_z_Ns,static_impulse_x_Ns,static_impulse_y_Ns,"
    "static_impulse_z_Ns,interpolation_weight,lateness_ns,active_planes,flags";

void format_row(std::ostream& out, const HapticLogRow& row) {
  CsvLine line(out);
  line.number(row.time_s).integer(static_cast<std::int64_t>(row.tick));
  line.numbers(row.finger_m).numbers(row.proxy_m).numbers(row.force_N);
  line.numbers(row.object_impulse_Ns).numbers(row.static_impulse_Ns);
  line.number(row.interpolation_weight).integer(row.lateness_ns).integer(row.active_planes).integer(row.flags);
}

constexpr const char* kToolLogHeader =
    "time_s,tick,grip_x_m,grip_y_m,grip_z_m,grip_qw,grip_qx,grip_qy,grip_qz,proxy_x_m,proxy_y_m,proxy_z_m,proxy_qw,"
    "proxy_qx,proxy_qy,proxy_qz,force_x_N,force_y_N,force_z_N,torque_x_Nm,torque_y_Nm,torque_z_Nm,active_contacts,"
    "flags";

void format_tool_row(std::ostream& out, const ToolLogRow& row) {
  CsvLine line(out);
  line.number(row.time_s).integer(static_cast<std::int64_t>(row.tick));
  line.numbers(row.grip_m).numbers(row.grip_wxyz).numbers(row.proxy_m).numbers(row.proxy_wxyz);
  line.numbers(row.force_N).numbers(row.torque_Nm).integer(row.active_contacts).integer(row.flags);
}

std::array<double, 4> wxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

ServoOptions servo_options(const HapticNodeOptions& options, const DeviceLimits& limits) {
  ServoOptions servo;
  servo.max_force_N = limits.max_force_N;
  servo.stiffness_Npm = options.stiffness_Npm;
  servo.damping_Nspm = options.damping_Nspm;
  servo.tick_period_s = 1.0 / options.rate_hz;
  return servo;
}

}  // namespace

HapticNode::HapticNode(const HapticNodeOptions& options, WorldLinkClient& world, HapticDevice& device)
    : options_(options), period_s_(1.0 / options.rate_hz), world_(world), device_(device) {
  const std::uint32_t fingers = device.finger_count();
  if (fingers == 0 || fingers > kMaxFingers || world.endpoints() != fingers) {
    throw std::invalid_argument("the device has " + std::to_string(fingers) + " finger(s) but the world link was " +
                                "opened for " + std::to_string(world.endpoints()) + " endpoint(s)");
  }
  if (options.clock == ClockMode::lockstep) {
    schedule_.emplace(LockstepSchedule::ticks_per_world_step(world.info().world_period_s, options.rate_hz),
                      world.info().phase_ticks);  // throws if not whole
  }
  if (options.tool.has_value() != device.oriented() || (options.tool && fingers != 1)) {
    throw std::invalid_argument(options.tool ? "a tool needs a device with one oriented grip (--device grip), not a "
                                               "device of fingers"
                                             : "an oriented device (grip) holds a tool: give the node the scene's "
                                               "tool (haptic_controller --tool-from SCENE; docs/tool.md)");
  }
  const ServoOptions servo = servo_options(options, device.limits());
  for (EndpointId k = 0; k < fingers; ++k) {
    endpoints_.push_back(std::make_unique<Endpoint>(servo, options.haptic_session, k));
    if (options.tool) {
      ToolCoupling coupling = options.tool_coupling;
      coupling.max_force_N = std::min(coupling.max_force_N, device.limits().max_force_N);
      coupling.max_torque_Nm = std::min(coupling.max_torque_Nm, device.limits().max_torque_Nm);
      endpoints_.back()->tool = std::make_unique<ToolServo>(*options.tool, coupling, options.haptic_session, k);
    } else {
      servos_.push_back(&endpoints_.back()->servo);
    }
    if (!options.log_path.empty()) {
      endpoints_.back()->log.emplace(endpoint_log_path(options.log_path, k), kLogHeader, format_row, kLogRows,
                                     options.clock == ClockMode::lockstep ? LogOverflow::wait : LogOverflow::drop,
                                     "haptic_controller");
      if (options.tool) {
        endpoints_.back()->tool_log.emplace(tool_log_path(options.log_path), kToolLogHeader, format_tool_row,
                                            kLogRows,
                                            options.clock == ClockMode::lockstep ? LogOverflow::wait
                                                                                 : LogOverflow::drop,
                                            "haptic_controller");
      }
    }
  }
}

std::uint64_t HapticNode::max_ticks() const {
  return options_.duration_s > 0.0 ? static_cast<std::uint64_t>(std::llround(options_.duration_s * options_.rate_hz))
                                   : std::numeric_limits<std::uint64_t>::max();
}

void HapticNode::receive_frames(double now_s) {
  for (std::size_t k = 0; k < endpoints_.size(); ++k) {
    if (!world_.receive_frame(static_cast<EndpointId>(k), frame_buffer_)) continue;
    if (endpoints_[k]->tool) {
      endpoints_[k]->tool->on_plane_frame(frame_buffer_, now_s);
    } else {
      endpoints_[k]->servo.on_plane_frame(frame_buffer_, now_s);
    }
  }
}

const HapticReport& HapticNode::report_of(const Endpoint& endpoint) {
  return endpoint.tool ? endpoint.tool->report() : endpoint.servo.report();
}

std::uint64_t HapticNode::ticks_of(const Endpoint& endpoint) {
  return endpoint.tool ? endpoint.tool->ticks() : endpoint.servo.counters().ticks;
}

std::uint64_t HapticNode::faults_of(const Endpoint& endpoint) {
  return endpoint.tool ? endpoint.tool->faults() : endpoint.servo.counters().faults;
}

void HapticNode::tick_tool(Endpoint& endpoint, const FingerSample* grip, double now_s, double dt_s,
                           FingerCommand& command) {
  // A reading that gives no pose is a fault (the servo renders nothing and counts it), as a finger's invalid sample.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  BodyPose pose{Eigen::Vector3d::Constant(kNaN), Eigen::Quaterniond::Identity()};
  if (grip != nullptr && grip->valid) pose = {grip->position_m, grip->orientation};
  const ToolTickResult& result = endpoint.tool->tick(grip != nullptr ? &pose : nullptr, now_s, dt_s);
  command.force_N = result.force_N;
  command.torque_Nm = result.torque_Nm;
  command.render = result.render;
}

// After the world's frames: the fingers, a servo tick per finger, the forces to the device, the reports to the
// world, a log row per finger.
void HapticNode::tick(std::uint64_t tick, double now_s, double dt_s, std::int64_t lateness_ns) {
  const FingerSample* fingers = device_.read(tick, now_s);
  // The servos' CPU time on every 64th tick: reading the thread's CPU clock is a system call (~1.4 µs here, more than
  // the tick it would measure), and a sample of 1 in 64 gives the same percentiles over any run of seconds.
  const bool sampled = (tick & 63u) == 0;
  const std::int64_t cpu_before_ns = sampled ? thread_cpu_now_ns() : 0;
  for (std::size_t k = 0; k < endpoints_.size(); ++k) {
    const FingerSample* finger = fingers != nullptr && fingers[k].present ? &fingers[k] : nullptr;
    if (endpoints_[k]->tool) {
      tick_tool(*endpoints_[k], finger, now_s, dt_s, commands_[k]);
      continue;
    }
    const TickResult& result = endpoints_[k]->servo.tick(finger, now_s, dt_s);
    commands_[k].force_N = to_eigen(result.force_N);
    commands_[k].render = result.render;
  }
  exchange_pushes(servos_);
  if (sampled) tick_cpu_ns_.record(thread_cpu_now_ns() - cpu_before_ns);
  bool world_present = false;
  for (const auto& endpoint : endpoints_) {
    world_present = world_present || (endpoint->tool ? endpoint->tool->has_world() : endpoint->servo.has_world());
  }
  device_.note_world(world_present);
  const std::uint32_t saturated = device_.command_fingers(tick, commands_.data());
  for (std::size_t k = 0; k < endpoints_.size(); ++k) {
    Endpoint& endpoint = *endpoints_[k];
    world_.publish_report(report_of(endpoint));
    if (endpoint.tool) {
      log_tool_tick(endpoint, tick, now_s, (saturated >> k) & 1u, lateness_ns);
      continue;
    }
    const TickResult& result = endpoint.servo.last_result();
    log_tick(endpoint, tick, now_s, result, (saturated >> k) & 1u, lateness_ns);
    if (result.render) {
      endpoint.stiffness_Npm = result.stiffness_Npm;
      endpoint.damping_Nspm = result.damping_Nspm;
    }
    endpoint.max_force_N = std::max(endpoint.max_force_N, std::sqrt(result.force_N[0] * result.force_N[0] +
                                                                    result.force_N[1] * result.force_N[1] +
                                                                    result.force_N[2] * result.force_N[2]));
  }
}

void HapticNode::log_tool_tick(Endpoint& endpoint, std::uint64_t tick, double now_s, bool saturated,
                               std::int64_t lateness_ns) {
  const ToolTickResult& result = endpoint.tool->last_result();
  endpoint.max_force_N = std::max(endpoint.max_force_N, result.force_N.norm());
  endpoint.max_torque_Nm = std::max(endpoint.max_torque_Nm, result.torque_Nm.norm());
  if (!endpoint.log) return;
  const std::uint32_t flags =
      (result.grip_valid ? 1u : 0u) | (saturated ? 2u : 0u) | (result.world_stale ? 8u : 0u);
  // The poses and the torque go to the tool's log; the haptic log's columns take the grip's centre as the finger, the
  // proxy's grip centre as the proxy and the force on the grip, so whatever reads a finger's log reads a tool's.
  ToolLogRow pose{};
  pose.tick = tick;
  pose.time_s = now_s;
  pose.grip_m = to_vec3(result.grip.position_m);
  pose.grip_wxyz = wxyz(result.grip.orientation);
  pose.proxy_m = to_vec3(result.proxy.position_m);
  pose.proxy_wxyz = wxyz(result.proxy.orientation);
  pose.force_N = to_vec3(result.force_N);
  pose.torque_Nm = to_vec3(result.torque_Nm);
  pose.active_contacts = result.active;
  pose.flags = flags;
  endpoint.tool_log->push(pose);
  const HapticReport& report = endpoint.tool->report();
  HapticLogRow row{};
  row.tick = tick;
  row.time_s = now_s;
  row.finger_m = to_vec3(result.grip.position_m);
  row.proxy_m = to_vec3(result.proxy.position_m);
  row.force_N = to_vec3(result.force_N);
  row.object_impulse_Ns = object_impulse_total_Ns(report);
  row.static_impulse_Ns = report.static_impulse_Ns;
  row.interpolation_weight = result.interpolation_weight;
  row.lateness_ns = lateness_ns;
  row.active_planes = result.active;
  row.flags = flags;
  endpoint.log->push(row);
}

void HapticNode::log_tick(Endpoint& endpoint, std::uint64_t tick, double now_s, const TickResult& result,
                          bool saturated, std::int64_t lateness_ns) {
  if (!endpoint.log) return;
  const HapticReport& report = endpoint.servo.report();
  HapticLogRow row{};
  row.tick = tick;
  row.time_s = now_s;
  row.finger_m = result.finger_m;
  row.proxy_m = result.proxy_m;
  row.force_N = result.force_N;
  row.object_impulse_Ns = object_impulse_total_Ns(report);
  row.static_impulse_Ns = report.static_impulse_Ns;
  row.interpolation_weight = result.interpolation_weight;
  row.lateness_ns = lateness_ns;
  row.active_planes = result.active_planes;
  row.flags = (result.finger_valid ? 1u : 0u) | (saturated ? 2u : 0u) | (result.fault ? 4u : 0u) |
              (result.world_stale ? 8u : 0u) | (result.sticking ? 16u : 0u);
  endpoint.log->push(row);
}

bool HapticNode::lockstep_tick(std::uint64_t t) {
  if (t >= max_ticks()) {
    duration_reached_ = true;  // the device was still playing: the trial was cut at --duration
    return false;
  }
  if (stop_requested() || !device_.wait_attached()) return false;
  // Exactly t·T: interpolation weights are then tick counts over n, the same in every run.
  const double now_s = static_cast<double>(t) * period_s_;
  tick(t, now_s, period_s_, 0);
  world_.lead_followers(t);  // other controllers on this world take tick t too, before the world steps
  // Frames are taken after every tick, not only after a step: a link with a delay line (the in-process link of a
  // latency experiment) hands a frame over d ticks after the step that sent it, whichever tick that is. Without a
  // delay nothing new arrives between steps, so the trial is the same.
  if (schedule_->world_step_due(t) && !world_.step_world(t)) {
    world_lost_ = true;
  } else {
    receive_frames(now_s);
  }
  if (t % kStatsEveryTicks == 0) publish_stats(nullptr);
  return true;
}

void HapticNode::finish_lockstep() {
  // A world that died after its last step (between two steps, as the session ended) left the trial unfinished too.
  if (!world_lost_ && !world_.world_alive()) world_lost_ = true;
  world_.end_session();
  device_.end_session();
  // A lockstep trial is one deterministic run: a world or device that left mid-way makes it incomplete, whatever came
  // after (each loss was reported when it happened).
  if (world_lost_ || device_.counters().devices_lost > 0) {
    std::fprintf(stderr, "haptic_controller: error: the trial is incomplete: the %s went away mid-trial (lockstep)\n",
                 world_lost_ ? "world manager" : "device");
    cut_short_ = true;
  }
}

// Lockstep time advances only while a device is attached: a lockstep run is in step with its device, so a session
// starts from the same state whenever the device attaches, and nothing is simulated while nobody is there.
void HapticNode::run_lockstep() {
  if (world_.follower()) {
    run_follower();
    return;
  }
  if (options_.followers > 0) {
    if (!world_.wait_for_followers(options_.followers)) {
      finish_lockstep();
      return;
    }
  }
  // A stop request is checked every tick: the followers' turns keep coming, so the stop must come from the master.
  for (std::uint64_t t = 0; lockstep_tick(t); ++t) {
  }
  finish_lockstep();
}

bool HapticNode::follow_tick(std::uint64_t t) {
  if (t > 0) receive_frames(static_cast<double>(t - 1) * period_s_);
  if (stop_requested() || !device_.wait_attached()) return false;
  tick(t, static_cast<double>(t) * period_s_, period_s_, 0);
  if (t % kStatsEveryTicks == 0) publish_stats(nullptr);
  return true;
}

// Another controller is the lockstep master: take its ticks as they come (follow_tick).
void HapticNode::run_follower() {
  const std::uint64_t ticks = max_ticks();
  bool master_lost = false;
  for (std::uint64_t done = 0; done < ticks;) {
    std::uint64_t t = 0;
    const TurnResult result = world_.wait_follower_turn(t);
    if (result != TurnResult::ok) {
      master_lost = result != TurnResult::shutdown && !stop_requested();
      if (master_lost) {
        std::fprintf(stderr, "haptic_controller: error: the lockstep master went away mid-trial: %s\n",
                     to_string(result));
      }
      break;
    }
    const bool attached = follow_tick(t);
    if (attached) ++done;
    world_.finish_follower_turn();
    if (!attached) break;
  }
  world_.end_session();  // leaves the master's turns
  device_.end_session();
  if (master_lost || device_.counters().devices_lost > 0) cut_short_ = true;
}

void HapticNode::run_realtime() {
  if (options_.realtime_priority) {
    const std::string warning = request_realtime(80);
    if (!warning.empty()) std::fprintf(stderr, "haptic_controller: warning: %s\n", warning.c_str());
  }
  std::atomic<bool> loop_done{false};
  std::thread supervisor([&] {
    while (!loop_done.load()) {
      world_.reattach();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  RealtimeClock clock(period_s_);
  const std::uint64_t ticks = max_ticks();
  while (!stop_requested() && clock.ticks() < ticks) {
    const TickTiming timing = clock.wait_next();
    receive_frames(timing.now_s);
    tick(timing.index, timing.now_s, timing.elapsed_s, timing.lateness_ns);
    if (timing.index % kStatsEveryTicks == 0) publish_stats(&clock);
  }
  if (clock.ticks() >= ticks) duration_reached_ = true;
  // The device's minimum output as the servo stops: the last force commanded would otherwise stay on the fingers.
  commands_.fill(FingerCommand{});
  device_.command_fingers(clock.ticks(), commands_.data());
  loop_done.store(true);
  supervisor.join();
  publish_stats(&clock);
  clock_stats_ = clock.lateness();
  skipped_periods_ = clock.skipped_periods();
}

int HapticNode::run() {
  if (options_.clock == ClockMode::lockstep) {
    // While the device or the world has the turn, this thread writes the endpoints' log rows.
    const LockstepIdleWork idle(
        [](void* node) {
          for (auto& endpoint : static_cast<HapticNode*>(node)->endpoints_) {
            if (endpoint->log && endpoint->log->drain_one()) return true;
            if (endpoint->tool_log && endpoint->tool_log->drain_one()) return true;
          }
          return false;
        },
        this);
    run_lockstep();
  } else {
    run_realtime();
  }
  return close();
}

int HapticNode::close() {
  publish_stats(nullptr);
  bool log_failed = false;
  for (auto& endpoint : endpoints_) {
    if (endpoint->log) {
      endpoint->log->close();
      log_failed = log_failed || endpoint->log->failed();
    }
    if (endpoint->tool_log) {
      endpoint->tool_log->close();
      log_failed = log_failed || endpoint->tool_log->failed();
    }
  }
  // A failed log write was reported when it happened (rt_log.h), a trial cut short at its end.
  return cut_short_ || log_failed ? 1 : 0;
}

void HapticNode::publish_stats(const RealtimeClock* clock) {
  LoopStats stats = loop_stats_now(clock);
  stats.ticks = ticks_of(*endpoints_[0]);
  stats.faults = 0;
  for (const auto& endpoint : endpoints_) stats.faults += faults_of(*endpoint);
  stats.rejected_frames = world_.rejected_frames() + device_.counters().rejected_frames;
  world_.publish_stats(stats);
}

nlohmann::json HapticNode::endpoint_summary(const Endpoint& endpoint) const {
  if (endpoint.tool) {
    const ToolServo& tool = *endpoint.tool;
    const HapticReport& report = tool.report();
    nlohmann::json impulses = nlohmann::json::object(), angular = nlohmann::json::object();
    for (std::uint32_t k = 0; k < report.entry_count; ++k) {
      const ObjectImpulse& entry = report.entries[k];
      const std::string id = std::to_string(entry.object_id);
      impulses[id] = {entry.impulse_Ns[0], entry.impulse_Ns[1], entry.impulse_Ns[2]};
      angular[id] = {entry.angular_impulse_Nms[0], entry.angular_impulse_Nms[1], entry.angular_impulse_Nms[2]};
    }
    const ToolCounters& proxy = tool.proxy().counters();
    return {{"endpoint", report.endpoint},
            {"haptic_session", options_.haptic_session},
            {"tool", true},
            {"faults", faults_of(endpoint)},
            {"force_clamps", proxy.clamps},
            {"pinches", proxy.pinches},
            {"unconverged", proxy.unconverged},
            {"log_rows_dropped",
             (endpoint.log ? endpoint.log->dropped() : 0) + (endpoint.tool_log ? endpoint.tool_log->dropped() : 0)},
            {"max_force_N", endpoint.max_force_N},
            {"max_torque_Nm", endpoint.max_torque_Nm},
            {"stiffness_Npm", tool.proxy().coupling().stiffness_Npm},
            {"rotational_stiffness_Nmprad", tool.proxy().coupling().rotational_stiffness_Nmprad},
            {"impulse_by_object_Ns", impulses},
            {"angular_impulse_by_object_Nms", angular},
            {"static_impulse_Ns",
             {report.static_impulse_Ns[0], report.static_impulse_Ns[1], report.static_impulse_Ns[2]}}};
  }
  const ServoCounters& counters = endpoint.servo.counters();
  nlohmann::json impulses = nlohmann::json::object();
  const HapticReport& report = endpoint.servo.report();
  for (std::uint32_t k = 0; k < report.entry_count; ++k) {
    const ObjectImpulse& entry = report.entries[k];
    impulses[std::to_string(entry.object_id)] = {entry.impulse_Ns[0], entry.impulse_Ns[1], entry.impulse_Ns[2]};
  }
  const Eigen::Vector3d& abandoned = endpoint.servo.accumulator().abandoned_impulse_Ns();
  // The passivity layer's half at the hand (hand_port.h): zeros with the layer off.
  const HandPortBooks& hand = endpoint.servo.hand_port().books();
  const nlohmann::json hand_port = {{"input_J", hand.input_J},       {"output_J", hand.output_J},
                                    {"credited_J", hand.credited_J}, {"returned_J", hand.returned_J},
                                    {"damped_J", hand.damped_J},     {"reservoir_J", hand.reservoir_J()},
                                    {"interventions", hand.interventions}};
  return {{"endpoint", report.endpoint},
          {"haptic_session", options_.haptic_session},
          {"faults", counters.faults},
          {"force_clamps", counters.force_clamps},
          {"infeasible_contacts", counters.infeasible_contacts},
          {"stale_world_ticks", counters.stale_world_ticks},
          {"no_device_ticks", counters.no_device_ticks},
          {"servo_stalls", counters.servo_stalls},
          {"dropped_impulse_shares", counters.dropped_impulse_shares},
          {"abandoned_impulse_Ns", {abandoned.x(), abandoned.y(), abandoned.z()}},
          {"contact_frame_boundaries", counters.contact_frame_boundaries},
          {"frame_jump_max_m", counters.frame_jump_max_m},
          {"local_model_error_max_m", counters.local_model_error_max_m},
          {"local_replayed_ticks_max", counters.local_replayed_ticks_max},
          {"local_replay_gaps", counters.local_replay_gaps},
          {"local_unlogged_shares", counters.local_unlogged_shares},
          {"hand_port", hand_port},
          {"link_round_trip_s", report.link_round_trip_s},
          {"log_rows_dropped", endpoint.log ? endpoint.log->dropped() : 0},
          {"max_force_N", endpoint.max_force_N},
          {"stiffness_Npm", endpoint.stiffness_Npm},
          {"damping_Nspm", endpoint.damping_Nspm},
          {"impulse_by_object_Ns", impulses},
          {"static_impulse_Ns", {report.static_impulse_Ns[0], report.static_impulse_Ns[1], report.static_impulse_Ns[2]}}};
}

nlohmann::json HapticNode::summary() const {
  // The first endpoint's figures at the top level (a one-finger trial's summary, as it always was), every
  // endpoint's under "endpoints"; the node's own (ticks, clock, device) once.
  nlohmann::json haptic = endpoint_summary(*endpoints_[0]);
  haptic.erase("endpoint");
  std::uint64_t faults = 0;
  nlohmann::json all = nlohmann::json::array();
  for (const auto& endpoint : endpoints_) {
    all.push_back(endpoint_summary(*endpoint));
    faults += faults_of(*endpoint);
  }
  haptic.update(nlohmann::json{
      {"ticks", ticks_of(*endpoints_[0])},
      {"rate_hz", options_.rate_hz},
      {"duration_reached", duration_reached_},
      {"faults", faults},
      {"saturations", device_.counters().saturations},
      {"devices_lost", device_.counters().devices_lost},
      {"channel_repairs", world_.channel_repairs() + device_.counters().channel_repairs},
      {"rejected_frames", world_.rejected_frames() + device_.counters().rejected_frames},
      {"world_attaches", world_.attaches()},
      {"force_limit_N", device_.limits().max_force_N},
      {"skipped_periods", skipped_periods_},
      {"lateness_p50_ns", clock_stats_.percentile_ns(0.5)},
      {"lateness_p99_ns", clock_stats_.percentile_ns(0.99)},
      {"lateness_p999_ns", clock_stats_.percentile_ns(0.999)},
      {"lateness_max_ns", clock_stats_.max_ns()},
      {"cpu_per_tick_p50_ns", tick_cpu_ns_.percentile_ns(0.5)},
      {"cpu_per_tick_p99_ns", tick_cpu_ns_.percentile_ns(0.99)},
      {"cpu_per_tick_mean_ns", tick_cpu_ns_.mean_ns()},
      {"cpu_per_tick_samples", tick_cpu_ns_.count()},  // every 64th tick
      {"endpoints", all}});
  if (nlohmann::json details = device_.details(); !details.is_null()) haptic["device"] = std::move(details);
  return {{"haptic", haptic}};
}

}  // namespace impetus
