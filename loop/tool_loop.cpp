// SPDX-License-Identifier: Apache-2.0
#include "loop/tool_loop.h"

#include "common/link/inproc/inproc_device_port.h"
#include "common/link/inproc/inproc_world_link.h"
#include "common/runtime/lockstep_schedule.h"
#include "common/spidar/grip_geometry.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/haptic_node.h"
#include "haptic_controller/tool/tool_servo.h"
#include "loop/in_process_rig.h"
#include "spidar_sim/grip_node.h"
#include "spidar_sim/grip_sim.h"
#include "world_manager/engine/engine_registry.h"
#include "world_manager/scene.h"
#include "world_manager/world.h"
#include "world_manager/world_node.h"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <mutex>
#include <stdexcept>

namespace impetus {
namespace {

constexpr double kTick_s = 1.0 / limits::kDefaultHapticRate_Hz;

// The world steps every n ticks: its period must be a whole number of ticks, as in every lockstep run. Said here in
// the option's own name, before anything is built (a scene's own rate is checked by the world node).
void check_world_rate(std::optional<double> world_rate_hz) {
  if (!world_rate_hz) return;
  try {
    if (!(*world_rate_hz >= limits::kMinWorldRate_Hz)) throw std::invalid_argument("");
    LockstepSchedule::ticks_per_world_step(1.0 / *world_rate_hz, limits::kDefaultHapticRate_Hz);
  } catch (const std::invalid_argument&) {
    char text[160];
    std::snprintf(text, sizeof text, "world_rate_hz: %g Hz is not a whole number of 1 ms ticks a period",
                  *world_rate_hz);
    throw std::invalid_argument(text);
  }
}

// The scene's tool; std::invalid_argument for a scene without one.
const SceneTool& tool_of(const Scene& scene) {
  if (!scene.tool) {
    throw std::invalid_argument(scene.source_name + ": has no \"tool\" block: a tool loop renders the scene's tool "
                                "(docs/scene-format.md)");
  }
  return *scene.tool;
}

bool finite(const GripPose& pose) { return pose.position_m.allFinite() && pose.orientation.coeffs().allFinite(); }

// The grip device's geometry, for its simulated end; std::invalid_argument naming the option for a spec that is not a
// grip device or a file that does not describe one.
SpidarGripGeometry grip_geometry(const std::string& spec) {
  try {
    return parse_grip_spec(spec).geometry;
  } catch (const SpidarGeometryError& error) {
    throw std::invalid_argument(std::string("device: ") + error.what());
  }
}

// Its host end, built by the registry as a daemon builds its device; it must be oriented (it holds a tool).
std::unique_ptr<HapticDevice> grip_driver(const std::string& spec, DevicePortHost& port) {
  std::unique_ptr<HapticDevice> driver = parse_device(spec)->make_finger(port, ClockMode::lockstep, 1);
  if (!driver->oriented()) throw std::invalid_argument("device: '" + spec + "' does not hold a tool (use grip)");
  return driver;
}

}  // namespace

// The nodes of the daemons, in one process (as loop/in_process_rig.h wires a finger's): the world node and the haptic
// node on an in-process world link; the haptic node serves the tool on the grip device, whose simulated end is on an
// in-process device port.
struct ToolLoop::Parts {
  explicit Parts(const ToolLoopOptions& options)
      : world(world_options(options)),
        link(world.link_info(),
             InProcessLinkDelay{0, LockstepSchedule::ticks_per_world_step(world.link_info().world_period_s,
                                                                          limits::kDefaultHapticRate_Hz)}),
        client(attach(link, world)),
        port(kTick_s),
        device(grip_geometry(options.device), options.hand, options.start),
        device_node(device, port, 1),
        driver(grip_driver(options.device, port)),
        haptic(haptic_options(tool_of(world.world().scene()), options), client, *driver),
        coupling(options.coupling) {
    port.connect(device_node);
  }

  static std::string log_path(const ToolLoopOptions& options, const char* name) {
    return options.out_dir.empty() ? std::string() : (std::filesystem::path(options.out_dir) / name).string();
  }
  static WorldNodeOptions world_options(const ToolLoopOptions& options) {
    WorldNodeOptions out;
    out.log_path = log_path(options, "world.csv");
    out.scene_path = options.scene_path.empty() ? "scene" : options.scene_path;
    out.scene_text = options.scene_text;
    out.rate_hz = options.world_rate_hz;
    out.coupling = options.coupling;
    out.clock = ClockMode::lockstep;
    out.world_session = 1;  // fixed: the run is one deterministic session
    return out;
  }
  static HapticNodeOptions haptic_options(const SceneTool& tool, const ToolLoopOptions& options) {
    HapticNodeOptions out;
    out.log_path = log_path(options, "haptic.csv");
    out.clock = ClockMode::lockstep;
    out.haptic_session = 1;
    out.realtime_priority = false;
    out.tool = tool.shape;
    out.tool_coupling = tool.coupling;
    return out;
  }
  static WorldLinkClient& attach(InProcessWorldLink& link, WorldNode& world) {
    world.connect(link);
    link.connect(world);
    return link.attach(1);
  }

  WorldNode world;
  InProcessWorldLink link;
  WorldLinkClient& client;
  // The device behind its port, as a daemon's would be: the simulated grip SPIDAR and its hand at the device end, the
  // driver at the host end (lockstep: the driver's read gives the device its tick).
  InProcessDevicePort port;
  GripSim device;
  GripNode device_node;
  std::unique_ptr<HapticDevice> driver;  // the grip's driver (grip_port_driver.h)
  HapticNode haptic;
  Coupling coupling;
};

ToolLoop::ToolLoop(const ToolLoopOptions& options) {
  if (options.coupling == Coupling::position) {
    throw std::invalid_argument("coupling: position coupling samples one point per endpoint, and a tool touches at "
                                "many; use local or impulse");
  }
  if (options.scene_path.empty() && options.scene_text.empty()) {
    throw std::invalid_argument("scene: give a scene file or its text");
  }
  if (!finite(options.start)) throw std::invalid_argument("start: the grip's start pose must be finite");
  const SpidarGripGeometry geometry = grip_geometry(options.device);
  if (const std::string problem = grip_point_problem(options.start.position_m, geometry); !problem.empty()) {
    throw std::invalid_argument("start: " + problem);
  }
  check_world_rate(options.world_rate_hz);
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  prepare_engines();
  parts_ = std::make_unique<Parts>(options);  // the world node reads the scene
  for (const SceneObject& object : parts_->world.world().scene().objects) object_names_.push_back(object.name);
}

ToolLoop::~ToolLoop() {
  try {
    finish();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "impetus: the tool loop did not finish cleanly: %s\n", error.what());
  }
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  parts_.reset();
}

double ToolLoop::tick_period_s() const { return kTick_s; }

void ToolLoop::check_target(const GripPose& target) const {
  if (!finite(target)) throw std::invalid_argument("target: the pose must be finite");
  const std::string problem = grip_point_problem(target.position_m, parts_->device.strings().geometry());
  if (!problem.empty()) throw std::invalid_argument("target: " + problem);
}

void ToolLoop::set_target(const GripPose& target) {
  check_target(target);
  parts_->device_node.steer({target.position_m, target.orientation.normalized()});
}

void ToolLoop::step(std::uint64_t count, std::span<const GripPose> targets, std::span<ToolTick> out) {
  if (finished_) throw std::logic_error("the tool loop has finished");
  if (!targets.empty() && targets.size() != count) throw std::invalid_argument("targets: must hold one pose a tick");
  if (!out.empty() && out.size() != count) throw std::invalid_argument("out: must hold one record a tick");
  for (const GripPose& target : targets) check_target(target);
  const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
  for (std::uint64_t i = 0; i < count; ++i) {
    if (!targets.empty()) parts_->device_node.steer({targets[i].position_m, targets[i].orientation.normalized()});
    tick(out.empty() ? nullptr : &out[i]);
  }
}

void ToolLoop::tick(ToolTick* out) {
  Parts& p = *parts_;
  // The haptic node's lockstep tick: the device's tick and its pose, the tool servo, the wrench to the device, the
  // report to the world, and the world's step when one is due.
  if (!p.haptic.lockstep_tick(ticks_)) throw std::logic_error("the tool loop's haptic node stopped");
  const double t_s = static_cast<double>(ticks_) * kTick_s;
  ++ticks_;
  if (out == nullptr) return;
  const ToolTickResult& result = p.haptic.tool_servo()->last_result();
  out->time_s = t_s;
  out->target = p.device_node.target();
  out->grip = {result.grip.position_m, result.grip.orientation};
  out->hand = p.device.pose();
  out->proxy = {result.proxy.position_m, result.proxy.orientation};
  out->force_N = result.force_N;
  out->torque_Nm = result.torque_Nm;
  const GripWrench strings = p.device.wrench();
  out->strings_force_N = strings.head<3>();
  out->strings_torque_Nm = strings.tail<3>();
  out->active = result.active;
}

std::vector<ToolLoopObject> ToolLoop::objects() const {
  std::vector<ToolLoopObject> out;
  const World& world = parts_->world.world();
  for (std::size_t i = 0; i < object_names_.size(); ++i) {
    const ObjectState& state = world.states()[i];
    out.push_back({state.pose, state.velocity_mps, state.angular_velocity_radps, world.total_impulse_Ns(i),
                   world.total_angular_impulse_Nms(i)});
  }
  return out;
}

const nlohmann::json& ToolLoop::finish() {
  if (finished_) return summary_;
  finished_ = true;
  Parts& p = *parts_;
  {
    const std::lock_guard<std::mutex> turn(InProcessRig::engine_turn());
    // The world applies a report at its next step: two more steps bring in the last ticks' impulse. Then the sessions
    // end.
    for (int k = 0; k < 2; ++k) p.client.step_world(ticks_ + static_cast<std::uint64_t>(k));
    p.haptic.finish_lockstep();
    p.haptic.close();
  }
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  nlohmann::json ledger = nlohmann::json::object();
  const ToolServo& servo = *p.haptic.tool_servo();
  const World& world = p.world.world();
  const HapticReport& report = servo.report();
  for (std::uint32_t e = 0; e < report.entry_count; ++e) {
    const ObjectImpulse& entry = report.entries[e];
    if (entry.object_id < 0 || static_cast<std::size_t>(entry.object_id) >= object_names_.size()) continue;
    const std::size_t id = static_cast<std::size_t>(entry.object_id);
    ledger[object_names_[id]] = {
        {"rendered_Ns", vec(to_eigen(entry.impulse_Ns))},
        {"applied_Ns", vec(world.total_impulse_Ns(id))},
        {"rendered_Nms", vec(to_eigen(entry.angular_impulse_Nms))},
        {"applied_Nms", vec(world.total_angular_impulse_Nms(id))},
    };
  }
  const ToolCounters& proxy = servo.proxy().counters();
  summary_ = {
      {"ticks", ticks_},
      {"coupling", to_string(p.coupling)},
      {"world_rate_hz", 1.0 / world.world_period_s()},
      {"tool", {{"faults", servo.faults()}, {"clamps", proxy.clamps}, {"pinches", proxy.pinches},
                {"unconverged", proxy.unconverged}}},
      {"device", p.driver->details()},
      {"ledger", ledger},
  };
  summary_.update(p.world.summary());
  summary_.update(p.haptic.summary());
  return summary_;
}

}  // namespace impetus
