// SPDX-License-Identifier: Apache-2.0
// The web hand (haptic_controller/device/web_hand.h) on a fake touch port and a fake clock: it rests absent until a
// page holds it, follows the pointer as a hand does, is pushed by the servo's force, and lets go of a silent or
// departed page at once, with the fingertip at rest and the minimum output.

#include "common/runtime/staleness.h"
#include "haptic_controller/device/device_registry.h"
#include "haptic_controller/device/web_hand.h"

#include "tests/support/allocation_counter.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace impetus;
using Eigen::Vector3d;

namespace {

std::int64_t g_now_ns = 0;
std::int64_t fake_clock() { return g_now_ns; }

class FakeTouchPort final : public TouchPortHost {
 public:
  bool latest_input(TouchInput& out) override {
    if (!written) return false;
    out = input;
    return true;
  }
  void publish_hand(const HandState& state) override {
    hand = state;
    ++hands;
  }
  std::uint64_t rejected_inputs() const override { return 0; }

  TouchInput input{};
  bool written = false;
  HandState hand{};
  std::uint64_t hands = 0;
};

// Drives a hand tick by tick at 1 kHz: the page's heartbeat refreshed every `heartbeat_ticks` (0: never).
struct Rig {
  explicit Rig(const WebHandParams& params = {}) : hand(params, port, &fake_clock) { g_now_ns = 1'000'000'000; }

  void hold(const Vector3d& target_m, std::uint64_t page = 1) {
    port.written = true;
    port.input.page = page;
    port.input.released_ns = 0;
    port.input.received_ns = g_now_ns;
    port.input.target_m = to_vec3(target_m);
  }
  const FingerSample& tick(bool heartbeat = true) {
    g_now_ns += 1'000'000;
    now_s += 1e-3;
    if (heartbeat && port.input.page != 0 && port.input.released_ns == 0) port.input.received_ns = g_now_ns;
    const FingerSample& sample = *hand.read(ticks, now_s);
    hand.command(ticks, force_N, true);
    ++ticks;
    return sample;
  }

  FakeTouchPort port;
  WebHand hand;
  Vector3d force_N = Vector3d::Zero();
  double now_s = 0.0;
  std::uint64_t ticks = 0;
};

}  // namespace

TEST_CASE("the web hand rests at its rest point with no finger until a page holds it") {
  Rig rig;
  for (int k = 0; k < 100; ++k) {
    const FingerSample& sample = rig.tick();
    CHECK_FALSE(sample.present);
    CHECK(sample.valid);
  }
  CHECK(rig.hand.finger().position_m().isApprox(Vector3d(0.0, 0.0, 0.05)));
  CHECK(rig.port.hands == 100);
  CHECK(rig.port.hand.page == 0);
  CHECK(rig.port.hand.workspace_min_m[2] == Approx(-0.15));
  CHECK(rig.port.hand.workspace_max_m[0] == Approx(0.2));
}

TEST_CASE("a held hand's target follows the pointer at most max_target_speed_mps, and the finger follows the target") {
  Rig rig;
  const Vector3d start = rig.hand.finger().position_m();
  const Vector3d goal = start + Vector3d(0.1, 0.0, 0.0);
  rig.hold(goal);
  double largest_step_m = 0.0;
  Vector3d last_target = start;
  for (int k = 0; k < 1000; ++k) {
    REQUIRE(rig.tick().present);
    largest_step_m = std::max(largest_step_m, (rig.hand.target_m() - last_target).norm());
    last_target = rig.hand.target_m();
  }
  // 1 m/s over a 1 ms tick: 1 mm, so 0.1 m takes 100 ticks.
  CHECK(largest_step_m == Approx(1e-3).epsilon(1e-9));
  CHECK(rig.hand.target_m().isApprox(goal));
  // The hand (300 N/m, 8 N·s/m, 0.1 kg; ζ ≈ 0.73) has settled 0.9 s after its target did.
  CHECK((rig.hand.finger().position_m() - goal).norm() < 1e-5);
  CHECK(rig.hand.hand_counters().holds == 1);
}

TEST_CASE("the servo's force pushes the held fingertip off its target by F/k, and is clamped to max_force_N") {
  Rig rig;
  const Vector3d target = rig.hand.finger().position_m();
  rig.hold(target);
  rig.force_N = Vector3d(3.0, 0.0, 0.0);
  for (int k = 0; k < 2000; ++k) rig.tick();
  // m·a = k_h·(target − x) + F at rest: x − target = F/k_h = 3 N / 300 N/m = 1 cm.
  CHECK(rig.hand.finger().position_m().x() - target.x() == Approx(0.01).epsilon(1e-6));
  CHECK(rig.hand.command(rig.ticks, Vector3d(0.0, 0.0, 25.0), true) == false);
  CHECK(rig.hand.counters().saturations == 1);
  for (int k = 0; k < 2000; ++k) {
    rig.hand.read(rig.ticks, rig.now_s += 1e-3);
    g_now_ns += 1'000'000;
    rig.port.input.received_ns = g_now_ns;
    rig.hand.command(rig.ticks++, Vector3d(0.0, 0.0, 25.0), true);
  }
  // Rendered as 10 N (the limit): 3.3 cm up.
  CHECK(rig.hand.finger().position_m().z() - target.z() == Approx(10.0 / 300.0).epsilon(1e-6));
}

TEST_CASE("a page silent for kTouchInputStale_s is let go on the next tick: no finger, no force, the fingertip at rest") {
  Rig rig;
  rig.hold(rig.hand.finger().position_m() + Vector3d(0.05, 0.0, 0.0));
  for (int k = 0; k < 30; ++k) rig.tick();  // moving
  REQUIRE(rig.hand.finger().velocity_mps().norm() > 0.1);
  const std::int64_t silent_from_ns = rig.port.input.received_ns;
  int ticks_present = 0;
  while (rig.tick(false).present) ++ticks_present;
  // Present while the page's last message is at most 40 ms old: 40 ticks; let go on the 41st.
  CHECK(ticks_present == static_cast<int>(std::lround(kTouchInputStale_s * 1e3)));
  CHECK(g_now_ns - silent_from_ns <= static_cast<std::int64_t>(kTouchInputStale_s * 1e9) + 1'000'000);
  const WebHandCounters& counters = rig.hand.hand_counters();
  CHECK(counters.timeouts == 1);
  CHECK(counters.releases == 0);
  CHECK(counters.last_release_ns == g_now_ns);
  CHECK(counters.max_release_delay_s == Approx(0.041));
  CHECK(rig.hand.finger().velocity_mps().norm() == 0.0);
  // Whatever the servo asks now, nothing moves the fingertip: minimum output.
  const Vector3d rest = rig.hand.finger().position_m();
  rig.force_N = Vector3d(5.0, 5.0, 5.0);
  for (int k = 0; k < 500; ++k) CHECK_FALSE(rig.tick(false).present);
  CHECK(rig.hand.finger().position_m() == rest);
  CHECK(rig.port.hand.page == 0);
}

TEST_CASE("a page that lets go (closed, hidden) is let go on the next tick, and a new hold starts at the fingertip") {
  Rig rig;
  rig.hold(rig.hand.finger().position_m() + Vector3d(0.0, 0.08, 0.0));
  for (int k = 0; k < 50; ++k) rig.tick();
  rig.port.input.released_ns = g_now_ns;
  CHECK_FALSE(rig.tick().present);
  CHECK(rig.hand.hand_counters().releases == 1);
  CHECK(rig.hand.hand_counters().max_release_delay_s == Approx(0.001));
  const Vector3d rest = rig.hand.finger().position_m();
  // Another page, pointing far away: the target starts at the fingertip and travels, no jump.
  rig.hold(rest + Vector3d(-0.1, 0.0, 0.0), 2);
  REQUIRE(rig.tick().present);
  CHECK((rig.hand.target_m() - rest).norm() <= 1e-3 + 1e-12);
  CHECK(rig.hand.hand_counters().holds == 2);
}

TEST_CASE("targets are kept inside the workspace, and a reception time from the future is no heartbeat") {
  WebHandParams params;
  params.workspace_side_m = 0.2;
  params.max_target_speed_mps = 10.0;
  Rig rig(params);
  rig.hold(Vector3d(3.0, -3.0, 0.01));
  for (int k = 0; k < 3000; ++k) rig.tick();
  CHECK(rig.hand.target_m().isApprox(Vector3d(0.1, -0.1, 0.01)));
  rig.port.input.received_ns = g_now_ns + 10'000'000'000;  // not written by this host's clock
  CHECK_FALSE(rig.tick(false).present);
}

#if IMPETUS_COUNT_ALLOCATIONS
TEST_CASE("the web hand's read() and command() allocate nothing") {
  Rig rig;
  rig.hold(Vector3d(0.05, 0.0, 0.05));
  rig.tick();
  impetus::test::start_counting_allocations();
  for (int k = 0; k < 10000; ++k) {
    if (k % 997 == 0) rig.port.input.released_ns = (k / 997) % 2 ? 0 : g_now_ns;
    rig.force_N = Vector3d(std::sin(k * 0.01), 0.0, 1.0);
    rig.tick();
  }
  CHECK(impetus::test::stop_counting_allocations() == 0);
}
#endif

TEST_CASE("the web device (web, web:FILE.json) runs in real time only, and its hand file's errors name the file and key") {
  const std::unique_ptr<DeviceType> type = parse_device("web");
  CHECK_FALSE(type->uses_device_ports());
  CHECK_THROWS_WITH(type->make_local("impetus_test_web_lockstep", ClockMode::lockstep),
                    Catch::Contains("--clock realtime"));
  const std::filesystem::path dir = std::filesystem::path(IMPETUS_BINARY_DIR) / "test-output" / "web-hand";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string good = write("good.json", R"({"mass_kg": 0.2, "rest_m": [0.05, 0, 0.05], "max_force_N": 4})");
  const WebHandParams params = load_web_hand(good);
  CHECK(params.hand.mass_kg == 0.2);
  CHECK(params.rest_m[0] == 0.05);
  CHECK(params.max_force_N == 4.0);
  CHECK(params.source == good);
  CHECK_THROWS_WITH(parse_device("web:" + (dir / "missing.json").string()), Catch::Contains("missing.json"));
  const std::string unknown = write("unknown.json", R"({"stiffness": 3})");
  CHECK_THROWS_WITH(load_web_hand(unknown), Catch::Contains("unknown.json") && Catch::Contains("stiffness"));
  const std::string outside = write("outside.json", R"({"workspace_side_m": 0.1, "rest_m": [0.3, 0, 0.05]})");
  CHECK_THROWS_WITH(load_web_hand(outside), Catch::Contains("/rest_m") && Catch::Contains("inside the workspace"));
  const std::string negative = write("negative.json", R"({"max_target_speed_mps": -1})");
  CHECK_THROWS_WITH(load_web_hand(negative), Catch::Contains("max_target_speed_mps"));
}
