// SPDX-License-Identifier: Apache-2.0
// Which page steers the web hand (viewer/touch_control.h), on a fake touch port and clock; and the touch port itself
// in shared memory (common/link/shm/shm_touch_port.h).

#include "common/link/shm/shm_touch_port.h"
#include "viewer/touch_control.h"
#include "viewer/viewer_node.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <limits>
#include <vector>

namespace impetus::view {
namespace {

std::int64_t g_now_ns = 5'000'000'000;
std::int64_t fake_clock() { return g_now_ns; }

class FakeClient final : public TouchPortClient {
 public:
  void publish_input(const TouchInput& input) override { inputs.push_back(input); }
  bool latest_hand(HandState& out) override {
    out = hand;
    return true;
  }
  std::vector<TouchInput> inputs;
  HandState hand{};
};

struct Rig {
  Rig() {
    control.emplace(
        [this]() -> std::unique_ptr<TouchPortClient> {
          if (!device_running) return nullptr;
          auto client = std::make_unique<FakeClient>();
          client->hand.finger_m = {0.01, 0.02, 0.05};
          port = client.get();
          return client;
        },
        "0123456789abcdef0123456789abcdef", &fake_clock);
  }
  nlohmann::json send(std::uint64_t page, const nlohmann::json& message, bool from_page = true) {
    bool ok = false;
    nlohmann::json reply = control->on_message(page, from_page, message, ok);
    last_ok = ok;
    return reply;
  }
  nlohmann::json take(std::uint64_t page, const std::string& token = "0123456789abcdef0123456789abcdef") {
    return send(page, {{"touch", "take"}, {"token", token}});
  }

  bool device_running = true;
  FakeClient* port = nullptr;
  std::optional<TouchControl> control;
  bool last_ok = false;
};

}  // namespace

TEST_CASE("touch: the page with the token takes the hand, its target starting where the fingertip rests") {
  Rig rig;
  const nlohmann::json reply = rig.take(7);
  CHECK(rig.last_ok);
  CHECK(reply["state"] == "holding");
  CHECK(reply["hand"]["finger_m"][1] == 0.02);
  REQUIRE(rig.port->inputs.size() == 1);
  CHECK(rig.port->inputs[0].page == 7);
  CHECK(rig.port->inputs[0].received_ns == g_now_ns);
  CHECK(rig.port->inputs[0].released_ns == 0);
  CHECK(rig.port->inputs[0].target_m == Vec3{0.01, 0.02, 0.05});
  g_now_ns += 10'000'000;
  CHECK(rig.send(7, {{"touch", "target"}, {"target_m", {0.1, 0.0, 0.03}}}).is_null());
  CHECK(rig.last_ok);
  REQUIRE(rig.port->inputs.size() == 2);
  CHECK(rig.port->inputs[1].target_m == Vec3{0.1, 0.0, 0.03});
  CHECK(rig.port->inputs[1].received_ns == g_now_ns);
  CHECK(rig.control->longest_gap_ns() == 10'000'000);
}

TEST_CASE("touch: a wrong token, a client that is no page, or a viewer without --touch never takes the hand") {
  Rig rig;
  CHECK(rig.take(1, "0123456789abcdef0123456789abcdee")["state"] == "refused");
  CHECK(rig.take(1, "")["state"] == "refused");
  CHECK(rig.send(1, {{"touch", "take"}, {"token", "0123456789abcdef0123456789abcdef"}}, false)["state"] == "refused");
  CHECK(rig.port == nullptr);  // nothing was written, the port not even opened
  CHECK(rig.control->refusals() == 3);
  bool ok = false;
  CHECK(TouchControl::without_touch({{"touch", "take"}, {"token", "x"}}, ok)["state"] == "unavailable");
  CHECK(ok);
}

TEST_CASE("touch: one page holds the hand, others watch until it lets go or closes") {
  Rig rig;
  REQUIRE(rig.take(1)["state"] == "holding");
  const nlohmann::json second = rig.take(2);
  CHECK(second["state"] == "watching");
  CHECK(second["reason"] == "another page holds the hand");
  // The watcher's targets move nothing.
  CHECK(rig.send(2, {{"touch", "target"}, {"target_m", {0.2, 0.2, 0.2}}})["state"] == "watching");
  CHECK(rig.port->inputs.size() == 1);
  // The holder lets go: the port says when; then the second page takes it.
  g_now_ns += 1'000'000;
  CHECK(rig.send(1, {{"touch", "release"}})["state"] == "released");
  REQUIRE(rig.port->inputs.size() == 2);
  CHECK(rig.port->inputs[1].page == 1);
  CHECK(rig.port->inputs[1].released_ns == g_now_ns);
  CHECK(rig.take(2)["state"] == "holding");
  CHECK(rig.port->inputs.back().page == 2);
  CHECK(rig.port->inputs.back().released_ns == 0);
  // Closing the holder's page lets go; closing a watcher's changes nothing.
  rig.control->page_closed(1);
  CHECK(rig.port->inputs.size() == 3);
  g_now_ns += 1'000'000;
  rig.control->page_closed(2);
  CHECK(rig.port->inputs.back().released_ns == g_now_ns);
  CHECK(rig.control->holder() == 0);
}

TEST_CASE("touch: malformed touch messages break the protocol, out-of-range targets too") {
  Rig rig;
  REQUIRE(rig.take(1)["state"] == "holding");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const nlohmann::json& bad : {nlohmann::json{{"touch", "grab"}},
                                    nlohmann::json{{"touch", 3}},
                                    nlohmann::json{{"touch", "target"}, {"target_m", {0.1, 0.2}}},
                                    nlohmann::json{{"touch", "target"}, {"target_m", {0.1, 0.2, "x"}}},
                                    nlohmann::json{{"touch", "target"}, {"target_m", {0.1, 0.2, nan}}},
                                    nlohmann::json{{"touch", "target"}, {"target_m", {0.1, 0.2, 1e3}}},
                                    nlohmann::json{{"touch", "target"}, {"target_m", {0, 0, 0}}, {"more", 1}},
                                    nlohmann::json{{"touch", "take"}, {"token", std::string(100, 'a')}},
                                    nlohmann::json{{"touch", "release"}, {"now", true}}}) {
    rig.send(1, bad);
    CHECK_FALSE(rig.last_ok);
  }
  CHECK(rig.port->inputs.size() == 1);
}

TEST_CASE("touch: with no web hand running a take is unavailable, and the port is looked for again later") {
  Rig rig;
  rig.device_running = false;
  const nlohmann::json reply = rig.take(1);
  CHECK(reply["state"] == "unavailable");
  rig.device_running = true;
  CHECK(rig.take(1)["state"] == "unavailable");  // looked for at most twice a second
  g_now_ns += 600'000'000;
  CHECK(rig.take(1)["state"] == "holding");
}

TEST_CASE("touch: tokens are 32 hexadecimal digits and differ from run to run") {
  const std::string a = new_touch_token();
  const std::string b = new_touch_token();
  CHECK(a.size() == 32);
  CHECK(a.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(a != b);
}

TEST_CASE("touch port in shared memory: input one way, the hand the other, unusable input dropped and counted") {
  const std::string shm = "impetus_touch_port_test_" + std::to_string(getpid());
  std::optional<ShmTouchPortHost> host(std::in_place, shm);
  ShmTouchPortClient client(shm);
  TouchInput in{};
  CHECK_FALSE(host->latest_input(in));
  TouchInput sent{};
  sent.page = 3;
  sent.received_ns = 42;
  sent.target_m = {0.1, -0.2, 0.3};
  client.publish_input(sent);
  REQUIRE(host->latest_input(in));
  CHECK(in.page == 3);
  CHECK(in.target_m == sent.target_m);
  TouchInput bad = sent;
  bad.target_m[1] = std::numeric_limits<double>::infinity();
  client.publish_input(bad);
  REQUIRE(host->latest_input(in));
  CHECK(in.target_m == sent.target_m);  // the last usable one
  CHECK(host->rejected_inputs() == 1);
  HandState hand{};
  hand.finger_m = {1.0, 2.0, 3.0};
  hand.page = 3;
  host->publish_hand(hand);
  HandState seen{};
  REQUIRE(client.latest_hand(seen));
  CHECK(seen.finger_m == hand.finger_m);
  CHECK(client.host_alive());
  host.reset();  // the device exits: its name goes
  CHECK_THROWS_AS(ShmTouchPortClient(shm), SegmentError);
}

}  // namespace impetus::view

namespace impetus::view {

TEST_CASE("touch: viewer --touch is refused with --allow-remote alone, and with a replay") {
  ViewerOptions options;
  options.touch = true;
  options.allow_remote = true;
  options.listen = "0.0.0.0:0";
  options.web_dir = std::string(IMPETUS_SOURCE_DIR) + "/viewer/web";
  CHECK_THROWS_WITH(ViewerNode(options, "viewer").run(), Catch::Contains("--allow-remote-touch"));
  options.allow_remote = false;
  options.listen = "127.0.0.1:0";
  options.replay_dir = std::string(IMPETUS_BINARY_DIR);
  CHECK_THROWS_WITH(ViewerNode(options, "viewer").run(), Catch::Contains("a replay has none"));
}

}  // namespace impetus::view
