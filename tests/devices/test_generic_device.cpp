// SPDX-License-Identifier: Apache-2.0
// The generic impedance device of docs/devices.md (examples/generic_device) against its simulated backend: the
// calibration into the world frame, the force back into the device frame, and the safety rules every device follows —
// minimum output without a fresh valid reading, the force limit, a lost device counted, zero force after the session —
// alone and under a lockstep haptic node. Also: read() and command() never touch the heap.

#include "common/runtime/process.h"
#include "examples/generic_device/generic_impedance_device.h"
#include "examples/generic_device/simulated_impedance_backend.h"
#include "haptic_controller/haptic_node.h"
#include "haptic_controller/servo.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "tests/support/allocation_counter.h"

using namespace impetus;
using impetus::test::start_counting_allocations;
using impetus::test::stop_counting_allocations;
using Eigen::Vector3d;

namespace {

// The device of examples/generic_device/generic_device.json: mounted on its side (its y axis is the world's z, its z
// axis the world's −y), reporting millimetres, its origin 5 cm above the world's.
GenericDeviceConfig mounted_on_its_side() {
  GenericDeviceConfig config;
  config.calibration.rotation_device_to_world << 1, 0, 0,  //
      0, 0, -1,                                            //
      0, 1, 0;
  config.calibration.offset_m = Vector3d(0.0, 0.0, 0.05);
  config.calibration.metres_per_unit = 0.001;
  config.workspace_min_m = Vector3d(-0.08, -0.06, -0.06);
  config.workspace_max_m = Vector3d(0.08, 0.06, 0.06);
  config.max_force_N = 3.0;
  config.max_reading_age_s = 0.01;
  return config;
}

// Resets the stop request a test raised, whatever happens.
struct StopRequestGuard {
  ~StopRequestGuard() { g_stop_requested.store(false); }
};

}  // namespace

TEST_CASE("generic device: a reading in device millimetres becomes the finger in the world frame") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  CHECK(device.limits().max_force_N == 3.0);
  CHECK(backend.writes() == 1);  // the constructor commands minimum output at once
  CHECK(backend.last_force_device_N() == Vector3d::Zero());

  backend.place(Vector3d(10.0, 20.0, -30.0));  // mm, device frame
  const FingerSample* sample = device.read(0, 0.0);
  REQUIRE(sample != nullptr);
  REQUIRE(sample->valid);
  // x_world = R · (0.001 · p) + offset = (0.010, 0.030, 0.020) + (0, 0, 0.05).
  CHECK((sample->position_m - Vector3d(0.010, 0.030, 0.070)).norm() < 1e-15);

  // The same through an arbitrary rotation and offset: the calibration is x_world = R·s·p + o, nothing else.
  GenericDeviceConfig tilted = mounted_on_its_side();
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  tilted.calibration.rotation_device_to_world = rotation;
  tilted.calibration.offset_m = Vector3d(0.1, -0.2, 0.3);
  GenericImpedanceDevice tilted_device(tilted, backend);
  const FingerSample* tilted_sample = tilted_device.read(0, 0.0);
  REQUIRE(tilted_sample != nullptr);
  REQUIRE(tilted_sample->valid);
  CHECK((tilted_sample->position_m - (rotation * Vector3d(0.010, 0.020, -0.030) + Vector3d(0.1, -0.2, 0.3))).norm() <
        1e-15);
}

TEST_CASE("generic device: a world-frame force reaches the backend rotated into the device frame") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  REQUIRE(device.read(0, 0.0) != nullptr);
  CHECK(device.command(0, Vector3d(1.0, -2.0, 0.5), true));  // |f| < 3 N: rendered exactly
  // Rᵀ f: the device's x is the world's x, its y the world's z, its z the world's −y.
  CHECK((backend.last_force_device_N() - Vector3d(1.0, 0.5, 2.0)).norm() < 1e-15);
  CHECK(device.counters().saturations == 0);

  GenericDeviceConfig tilted = mounted_on_its_side();
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(2.1, Vector3d(0.3, 0.4, -1.0).normalized()).toRotationMatrix();
  tilted.calibration.rotation_device_to_world = rotation;
  GenericImpedanceDevice tilted_device(tilted, backend);
  REQUIRE(tilted_device.read(1, 1e-3) != nullptr);
  const Vector3d force_N(-0.4, 1.1, 2.2);
  CHECK(tilted_device.command(1, force_N, true));
  CHECK((rotation * backend.last_force_device_N() - force_N).norm() < 1e-14);  // back in the world: the same force
  CHECK(std::abs(backend.last_force_device_N().norm() - force_N.norm()) < 1e-14);  // a rotation keeps the magnitude
}

TEST_CASE("generic device: a stale reading gives no finger, and render=false commands zero force") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);  // max_reading_age_s = 10 ms
  REQUIRE(device.read(0, 0.0) != nullptr);
  REQUIRE(device.command(0, Vector3d(0.0, 0.0, 1.0), true));
  REQUIRE(backend.last_force_device_N().norm() > 0.9);

  backend.go_silent();  // still connected, nothing new: the last reading ages
  const FingerSample* aging = device.read(1, 0.009);
  REQUIRE(aging != nullptr);  // 9 ms old: still fresh
  CHECK(aging->valid);
  CHECK(device.read(2, 0.0101) == nullptr);  // 10.1 ms old: stale
  CHECK(device.stale_reads() == 1);
  device.command(2, Vector3d(0.0, 0.0, 1.0), false);  // what the servo sends without a finger
  CHECK(backend.last_force_device_N() == Vector3d::Zero());
  // Even a render request cannot push on a finger this tick's read() did not give.
  CHECK(device.command(2, Vector3d(0.0, 0.0, 1.0), true));
  CHECK(backend.last_force_device_N() == Vector3d::Zero());

  // A reading that was already too old on arrival, or whose age the backend got wrong, is stale too.
  backend.answer();
  backend.set_age_s(0.02);
  CHECK(device.read(3, 0.011) == nullptr);
  backend.set_age_s(-0.001);
  CHECK(device.read(4, 0.012) == nullptr);
  backend.set_age_s(std::nan(""));
  CHECK(device.read(5, 0.013) == nullptr);
  CHECK(device.stale_reads() == 4);
  backend.set_age_s(0.004);
  const FingerSample* fresh = device.read(6, 0.014);
  REQUIRE(fresh != nullptr);
  CHECK(fresh->valid);
  CHECK(device.counters().rejected_frames == 0);  // stale is not broken
}

TEST_CASE("generic device: a NaN or out-of-workspace reading is rejected, counted, and gets zero force") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  backend.return_nan();
  const FingerSample* sample = device.read(0, 0.0);
  // The device answered but its reading is unusable: a sample marked invalid (haptic_device.h), not nullptr.
  REQUIRE(sample != nullptr);
  CHECK_FALSE(sample->valid);
  CHECK(device.counters().rejected_frames == 1);
  CHECK(device.command(0, Vector3d(0.0, 0.0, 2.0), true));
  CHECK(backend.last_force_device_N() == Vector3d::Zero());

  // The servo takes such a sample as a fault: no force, counted (servo.h).
  HapticServo servo(ServoOptions{}, 1);
  const TickResult& result = servo.tick(sample, 0.0, 1e-3);
  CHECK_FALSE(result.render);
  CHECK(servo.counters().faults == 1);

  REQUIRE(device.read(1, 1e-3) != nullptr);  // a second NaN reading: counted once more
  CHECK(device.counters().rejected_frames == 2);

  backend.place(Vector3d(0.0, 0.0, 61.0));  // 61 mm along the device's z: outside its ±60 mm workspace
  sample = device.read(2, 2e-3);
  REQUIRE(sample != nullptr);
  CHECK_FALSE(sample->valid);
  CHECK(device.counters().rejected_frames == 3);

  backend.place(Vector3d(0.0, 0.0, 59.0));
  sample = device.read(3, 3e-3);
  REQUIRE(sample != nullptr);
  CHECK(sample->valid);
  CHECK(device.command(3, Vector3d(0.0, 0.0, 2.0), true));
  CHECK((backend.last_force_device_N() - Vector3d(0.0, 2.0, 0.0)).norm() < 1e-15);
}

TEST_CASE("generic device: a force above the limit is scaled to max_force_N in the same direction and counted") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);  // 3 N
  REQUIRE(device.read(0, 0.0) != nullptr);

  const Vector3d force_N(6.0, 0.0, -8.0);  // 10 N
  CHECK_FALSE(device.command(0, force_N, true));
  CHECK(device.counters().saturations == 1);
  const Vector3d written = backend.last_force_device_N();
  CHECK(std::abs(written.norm() - 3.0) < 1e-14);
  CHECK((written - Vector3d(1.8, -2.4, 0.0)).norm() < 1e-14);  // Rᵀ · 0.3 · (6, 0, −8)
  CHECK((mounted_on_its_side().calibration.rotation_device_to_world * written).normalized().dot(force_N.normalized()) >
        1.0 - 1e-15);

  CHECK(device.command(0, Vector3d(3.0, 0.0, 0.0), true));  // at the limit: exact, not counted
  CHECK(device.counters().saturations == 1);
  // A force the servo already scaled to the limit, f·(3/|f|), is often an ulp above 3 N: rendered, not counted.
  int above_by_rounding = 0;
  for (int k = 1; k <= 100; ++k) {
    const Vector3d direction(std::sin(1.1 * k), std::cos(0.7 * k), std::sin(0.3 * k + 1.0));
    const Vector3d at_limit_N = direction * (3.0 / direction.norm());
    if (at_limit_N.stableNorm() > 3.0) ++above_by_rounding;
    CHECK(device.command(0, at_limit_N, true));
  }
  CHECK(above_by_rounding > 0);  // the case arose
  CHECK(device.counters().saturations == 1);

  // A huge finite force still keeps its direction (its norm must not overflow to infinity and scale it to zero).
  CHECK_FALSE(device.command(0, Vector3d(1e300, 1e300, 0.0), true));
  CHECK(std::abs(backend.last_force_device_N().norm() - 3.0) < 1e-12);
  CHECK((backend.last_force_device_N() - Vector3d(1.0, 0.0, -1.0).normalized() * 3.0).norm() < 1e-12);
  CHECK(device.counters().saturations == 2);

  // A non-finite force never reaches the motors.
  CHECK_FALSE(device.command(0, Vector3d(std::nan(""), 1.0, 0.0), true));
  CHECK(backend.last_force_device_N() == Vector3d::Zero());
  CHECK(device.refused_forces() == 1);
  CHECK(device.counters().saturations == 2);
}

TEST_CASE("generic device: after end_session every command writes zero force, and so does destruction") {
  SimulatedImpedanceBackend backend;
  {
    GenericImpedanceDevice device(mounted_on_its_side(), backend);
    REQUIRE(device.read(0, 0.0) != nullptr);
    REQUIRE(device.command(0, Vector3d(0.0, 0.0, 1.5), true));
    REQUIRE(backend.last_force_device_N().norm() > 1.4);
    device.end_session();
    CHECK(backend.last_force_device_N() == Vector3d::Zero());
    CHECK(device.read(1, 1e-3) == nullptr);
    device.command(1, Vector3d(0.0, 0.0, 1.5), true);
    CHECK(backend.last_force_device_N() == Vector3d::Zero());
    CHECK_FALSE(device.wait_attached());  // the session is over: nothing to wait for
  }
  {
    GenericImpedanceDevice device(mounted_on_its_side(), backend);
    REQUIRE(device.read(0, 0.0) != nullptr);
    REQUIRE(device.command(0, Vector3d(0.0, 0.0, 1.5), true));
    REQUIRE(backend.last_force_device_N().norm() > 1.4);
  }  // a process may end without end_session() (an exception): the destructor must stop pushing
  CHECK(backend.last_force_device_N() == Vector3d::Zero());
}

TEST_CASE("generic device: a device that vanishes mid-session counts as lost, but a backend that closes does not") {
  SimulatedImpedanceBackend backend;
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  REQUIRE(device.wait_attached());
  REQUIRE(device.read(0, 0.0) != nullptr);

  backend.unplug();
  CHECK(device.read(1, 1e-3) == nullptr);
  CHECK(device.counters().devices_lost == 1);
  CHECK(device.read(2, 2e-3) == nullptr);
  CHECK(device.counters().devices_lost == 1);  // one loss, however many ticks it lasts

  // Plugged in again but silent: the old reading (2 ms old, so "fresh") is not used for the new device.
  backend.go_silent();
  backend.plug_in();
  CHECK(device.read(3, 3e-3) == nullptr);
  backend.answer();
  REQUIRE(device.read(4, 4e-3) != nullptr);

  backend.close();
  CHECK(device.read(5, 5e-3) == nullptr);
  CHECK_FALSE(device.wait_attached());  // closed: no device will come
  CHECK(device.counters().devices_lost == 1);
}

TEST_CASE("generic device: configurations that cannot be calibrated are refused, naming the key") {
  CHECK(generic_device_config_error(mounted_on_its_side()).empty());
  CHECK_THAT(generic_device_config_error(GenericDeviceConfig{}),
             Catch::StartsWith("rotation_device_to_world: must hold nine finite numbers"));  // nothing set: NaN

  GenericDeviceConfig config = mounted_on_its_side();
  config.calibration.rotation_device_to_world(2, 2) = -1.0;  // 1 0 0 / 0 0 −1 / 0 1 −1: not orthonormal
  CHECK_THAT(generic_device_config_error(config), Catch::StartsWith("rotation_device_to_world: must be orthonormal"));
  config.calibration.rotation_device_to_world = -Eigen::Matrix3d::Identity();  // orthonormal, but a reflection
  CHECK_THAT(generic_device_config_error(config), Catch::Contains("not a reflection"));

  config = mounted_on_its_side();
  config.max_reading_age_s = 0.2;  // more lenient than the project's 50 ms
  CHECK_THAT(generic_device_config_error(config), Catch::StartsWith("max_reading_age_s:"));
  config = mounted_on_its_side();
  config.workspace_max_m.y() = config.workspace_min_m.y();
  CHECK_THAT(generic_device_config_error(config), Catch::StartsWith("workspace_max_m: must exceed"));
  config = mounted_on_its_side();
  config.max_force_N = 0.0;
  CHECK_THAT(generic_device_config_error(config), Catch::StartsWith("max_force_N:"));
  SimulatedImpedanceBackend backend;
  CHECK_THROWS_AS(GenericImpedanceDevice(config, backend), std::invalid_argument);
  CHECK(backend.writes() == 0);  // nothing reached the device
}

TEST_CASE("generic device: the example device file loads, and a bad one is refused naming the file and the key") {
  const GenericDeviceConfig loaded =
      load_generic_device_config(std::string(IMPETUS_SOURCE_DIR) + "/examples/generic_device/generic_device.json");
  const GenericDeviceConfig expected = mounted_on_its_side();
  CHECK(loaded.calibration.rotation_device_to_world == expected.calibration.rotation_device_to_world);
  CHECK(loaded.calibration.offset_m == expected.calibration.offset_m);
  CHECK(loaded.calibration.metres_per_unit == expected.calibration.metres_per_unit);
  CHECK(loaded.workspace_min_m == expected.workspace_min_m);
  CHECK(loaded.workspace_max_m == expected.workspace_max_m);
  CHECK(loaded.max_force_N == expected.max_force_N);
  CHECK(loaded.max_reading_age_s == expected.max_reading_age_s);

  const std::filesystem::path path =
      std::filesystem::path(IMPETUS_BINARY_DIR) / ("generic-device-" + std::to_string(getpid()) + ".json");
  auto refused = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      load_generic_device_config(path.string());
    } catch (const GenericDeviceConfigError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  const std::string identity = R"("rotation_device_to_world": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], )";
  const std::string offset = R"("offset_m": [0, 0, 0.05], )";
  const std::string rest = R"("metres_per_unit": 0.001, "workspace_min_m": [-0.08, -0.06, -0.06],
                              "workspace_max_m": [0.08, 0.06, 0.06], "max_force_N": 3)";
  const std::string valid_rest = offset + rest;
  CHECK(refused("{" + identity + valid_rest + "}") == "accepted");  // max_reading_age_s may be left out
  CHECK_THAT(refused("{" + valid_rest + "}"), Catch::Contains(path.string() + ": rotation_device_to_world: missing"));
  CHECK_THAT(refused("{" + identity + valid_rest + R"(, "max_torque_Nm": 1})"),
             Catch::Contains("max_torque_Nm: unknown key"));
  CHECK_THAT(refused(R"({"rotation_device_to_world": [[1, 0], [0, 1]], )" + valid_rest + "}"),
             Catch::Contains("rotation_device_to_world: must be three rows of three numbers"));
  CHECK_THAT(refused("{" + identity + R"("offset_m": [0, 0, "5 cm"], )" + rest + "}"),
             Catch::Contains("offset_m: must be a number"));
  CHECK_THAT(refused("{" + identity + valid_rest + R"(, "max_reading_age_s": 0.5})"),
             Catch::Contains("max_reading_age_s: must be positive and at most"));
  CHECK_THAT(refused("[1, 2]"), Catch::Contains("must be a JSON object"));
  std::filesystem::remove(path);
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("generic device: read() and command() allocate nothing over 10^4 ticks of faults") {
  SimulatedImpedanceBackend backend;
  backend.move_each_reading(Vector3d(0.001, -0.002, 0.0015));
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  start_counting_allocations();
  for (int tick = 0; tick < 10000; ++tick) {
    const double now_s = tick * 1e-3;
    if (tick % 1000 == 100) backend.go_silent();
    if (tick % 1000 == 150) backend.answer();
    if (tick % 1000 == 300) backend.return_nan();
    if (tick % 1000 == 301) backend.place(Vector3d(1.0, 2.0, 3.0));
    if (tick % 1000 == 500) backend.unplug();
    if (tick % 1000 == 510) backend.plug_in();
    const FingerSample* sample = device.read(static_cast<std::uint64_t>(tick), now_s);
    const double size_N = 1.0 + (tick % 7);  // some within 3 N, some saturated
    device.command(static_cast<std::uint64_t>(tick), Vector3d(size_N, -0.5 * size_N, 0.2), sample && sample->valid);
  }
  CHECK(stop_counting_allocations() == 0);
  CHECK(device.counters().saturations > 0);      // every path was taken: saturation,
  CHECK(device.counters().rejected_frames > 0);  // rejection,
  CHECK(device.counters().devices_lost == 10);   // loss,
  CHECK(device.stale_reads() > 0);               // staleness
}

TEST_CASE("generic device: the allocation counter does count (the test above can fail)") {
  start_counting_allocations();
  // A call of operator new, not a new-expression: the compiler may elide an unused new-expression.
  void* p = ::operator new(sizeof(int));
  const long allocations = stop_counting_allocations();
  ::operator delete(p);
  CHECK(allocations == 1);
}
#endif

namespace {

// A world of one static floor, z = 0, at 20 Hz: every world step republishes it (a lockstep world link without ODE).
// In real time the floor's one frame is waiting from the start (nothing steps this world).
class FloorWorld final : public WorldLinkClient {
 public:
  explicit FloorWorld(ClockMode clock = ClockMode::lockstep) : pending_(clock == ClockMode::realtime) {
    info_.world_rate_hz = 20.0;
    info_.world_period_s = 0.05;
    info_.clock = clock;
    frame_.world_session = 1;
    frame_.world_period_s = info_.world_period_s;
    frame_.stiffness_Npm = 2000.0;
    Plane& floor = frame_.planes[frame_.plane_count++];
    floor.object_id = 0;
    floor.normal = {0.0, 0.0, 1.0};
    floor.com_m = {0.0, 0.0, -0.5};
  }
  const WorldLinkInfo& info() const override { return info_; }
  std::uint32_t endpoints() const override { return 1; }
  bool receive_frame(EndpointId, PlaneFrame& out) override {
    if (!pending_) return false;
    pending_ = false;
    out = frame_;
    return true;
  }
  void publish_report(const HapticReport& report) override { last_report = report; }
  void publish_stats(const LoopStats&) override {}
  bool step_world(std::uint64_t) override {
    frame_.frame_index = steps_++;
    frame_.world_time_s = static_cast<double>(steps_) * info_.world_period_s;
    pending_ = true;
    return true;
  }
  void end_session() override { ended = true; }
  bool reattach() override { return false; }
  std::uint64_t rejected_frames() const override { return 0; }
  std::uint64_t attaches() const override { return 1; }

  HapticReport last_report{};
  bool ended = false;

 private:
  WorldLinkInfo info_;
  PlaneFrame frame_{};
  bool pending_;
  std::uint64_t steps_ = 0;
};

// Forwards to a simulated backend until its `lose_after`-th reading; then the device is gone (absent) and, after a few
// attach polls, the user stops the run — as with a real device unplugged in a lockstep trial.
class LostMidTrial final : public ImpedanceBackend {
 public:
  LostMidTrial(SimulatedImpedanceBackend& sim, std::uint64_t lose_after) : sim_(sim), lose_after_(lose_after) {}
  BackendState state() const override {
    if (sim_.readings() < lose_after_) return sim_.state();
    if (++absent_queries_ >= 3) g_stop_requested.store(true);  // Ctrl-C
    return BackendState::absent;
  }
  bool poll(DeviceReading& out) override { return sim_.poll(out); }
  void write_force(const Eigen::Vector3d& force_device_N) override { sim_.write_force(force_device_N); }

 private:
  SimulatedImpedanceBackend& sim_;
  std::uint64_t lose_after_;
  mutable int absent_queries_ = 0;
};

HapticNodeOptions lockstep_options() {
  HapticNodeOptions options;
  options.clock = ClockMode::lockstep;
  options.realtime_priority = false;
  return options;
}

}  // namespace

TEST_CASE("generic device under a lockstep haptic node: a floor pressed 1 cm deep is felt at the device's limit") {
  // The finger starts 1 cm above the floor (device y = −40 mm) and sinks 0.1 mm per tick for 200 ticks; the device
  // then closes, which ends a lockstep run cleanly.
  SimulatedImpedanceBackend backend;
  backend.place(Vector3d(0.0, -40.0, 0.0));
  backend.move_each_reading(Vector3d(0.0, -0.1, 0.0));
  backend.close_after_readings(200);
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  FloorWorld world;
  HapticNode node(lockstep_options(), world, device);

  CHECK(node.run() == 0);
  CHECK(world.ended);
  CHECK(node.servo().counters().ticks == 200);
  CHECK(node.servo().counters().faults == 0);
  // 9.9 mm deep at 2 kN/m asks for ~20 N; the servo clamps to limits().max_force_N before command(), so the
  // device's own clamp has nothing left to do.
  CHECK(node.servo().counters().force_clamps > 0);
  CHECK(device.counters().saturations == 0);
  CHECK(device.counters().devices_lost == 0);
  // Felt along the world's +z, which is the device's +y: exactly 3 N there.
  CHECK((backend.largest_force_device_N() - Vector3d(0.0, 3.0, 0.0)).norm() < 1e-9);
  CHECK(backend.last_force_device_N() == Vector3d::Zero());  // end_session: minimum output
  // The servo saw the calibrated finger: the last reading, −59.9 mm along the device's y, is 9.9 mm below the floor.
  CHECK(std::abs(world.last_report.finger_m[2] - (0.05 - 0.0599)) < 1e-12);
  CHECK(world.last_report.static_impulse_Ns[2] < 0.0);  // the reaction went into the floor
  const nlohmann::json summary = node.summary()["haptic"];
  CHECK(summary["max_force_N"].get<double>() <= 3.0 + 1e-12);
  CHECK(summary["force_limit_N"].get<double>() == 3.0);
}

TEST_CASE("generic device under a lockstep haptic node: a device lost mid-trial makes the trial incomplete") {
  const StopRequestGuard guard;
  SimulatedImpedanceBackend sim;
  LostMidTrial backend(sim, 50);
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  FloorWorld world;
  HapticNode node(lockstep_options(), world, device);

  CHECK(node.run() == 1);  // lockstep: a device lost mid-trial is a failure, even after a stop request
  CHECK(device.counters().devices_lost == 1);
  CHECK(node.summary()["haptic"]["devices_lost"] == 1);
  CHECK(node.servo().counters().ticks == 50);
  CHECK(sim.last_force_device_N() == Vector3d::Zero());
}

TEST_CASE("generic device under a real-time haptic node: the device is left at minimum output when the servo stops") {
  // A finger that sinks from 1 cm above the floor, 0.1 mm per tick, for 0.2 s of real time: pushed out once it is in
  // (a finger that starts inside is not pushed out), and released when the run ends (a real-time node never calls
  // end_session(), so the stop itself must command the minimum).
  SimulatedImpedanceBackend backend;
  backend.place(Vector3d(0.0, -40.0, 0.0));  // world z = 50 mm − 40 mm
  backend.move_each_reading(Vector3d(0.0, -0.1, 0.0));
  GenericImpedanceDevice device(mounted_on_its_side(), backend);
  FloorWorld world(ClockMode::realtime);
  HapticNodeOptions options;
  options.clock = ClockMode::realtime;
  options.realtime_priority = false;
  options.duration_s = 0.2;
  HapticNode node(options, world, device);

  CHECK(node.run() == 0);
  CHECK(backend.largest_force_device_N()[1] > 1.0);  // it pushed the finger out of the floor (2 kN/m, up to 10 mm)
  CHECK(backend.last_force_device_N() == Vector3d::Zero());
}
