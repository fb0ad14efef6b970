// SPDX-License-Identifier: Apache-2.0
// The delay line of the in-process world link (common/link/inproc/): frames and reports arrive d haptic ticks late,
// deterministically, and the impulse ledger stays exact through it.

#include "common/link/inproc/delay_line.h"
#include "common/link/inproc/inproc_world_link.h"
#include "loop/in_process_trial.h"
#include "tests/integration/trial_support.h"

#include <catch2/catch.hpp>

#include <iomanip>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace impetus {
namespace {

// A world that, at each step, records which report tick it read per slot (0: none) and sends every slot a frame that
// carries the link's tick in frame_index, so a receiver can tell when the frame was sent.
class RecordingWorld final : public WorldStepper {
 public:
  explicit RecordingWorld(InProcessWorldLink& link) : link_(link) {}
  void step_world() override {
    for (std::uint32_t slot = 0; slot < link_.endpoint_slots(); ++slot) {
      HapticReport report;
      read_ticks.push_back(link_.latest_report(slot, report) ? report.tick : 0);
      PlaneFrame frame;
      frame.endpoint = slot;
      frame.frame_index = now_ticks;
      link_.publish_frame(slot, frame);
    }
  }
  std::uint64_t now_ticks = 0;           // the tick the test says the world is at
  std::vector<std::uint64_t> read_ticks;  // per step and slot, in order

 private:
  InProcessWorldLink& link_;
};

HapticReport report_of(std::uint64_t tick, EndpointId endpoint = 0) {
  HapticReport report;
  report.tick = tick;
  report.haptic_session = 1;
  report.endpoint = endpoint;
  return report;
}

WorldLinkInfo lockstep_info() {
  WorldLinkInfo info;
  info.world_rate_hz = 100.0;
  info.world_period_s = 0.01;
  info.clock = ClockMode::lockstep;
  return info;
}

// The haptic log's rendered impulse on the objects (object_impulse_* columns) at each tick, by tick.
std::vector<std::array<double, 3>> rendered_by_tick(const std::filesystem::path& haptic_csv) {
  std::istringstream text(test::read_text(haptic_csv));
  std::string line;
  std::getline(text, line);
  std::vector<std::string> header;
  for (std::istringstream cells(line); std::getline(cells, line, ',');) header.push_back(line);
  const auto column = [&](const std::string& name) {
    for (std::size_t k = 0; k < header.size(); ++k) {
      if (header[k] == name) return k;
    }
    FAIL("no column " << name);
    return std::size_t{0};
  };
  const std::size_t tick_column = column("tick");
  const std::size_t x_column = column("object_impulse_x_Ns");
  std::vector<std::array<double, 3>> rendered;
  for (std::string row; std::getline(text, row);) {
    std::vector<double> values;
    for (std::istringstream cells(row); std::getline(cells, line, ',');) values.push_back(std::stod(line));
    REQUIRE(static_cast<std::size_t>(values[tick_column]) == rendered.size());  // one row per tick, in order
    rendered.push_back({values[x_column], values[x_column + 1], values[x_column + 2]});
  }
  return rendered;
}

InProcessTrialOptions tap_options(Coupling coupling, std::uint64_t phase_ticks, double link_delay_s) {
  InProcessTrialOptions options;
  options.scene_path = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  options.trajectory = "tap";
  options.coupling = coupling;
  options.phase_ticks = phase_ticks;
  options.link_delay_s = link_delay_s;
  return options;
}

}  // namespace

TEST_CASE("a delay line hands a value over d ticks after it was sent, never before, newest first") {
  DelayLine<int> line;
  line.reset(3, 5);
  CHECK(line.take_newest_due(100).value == nullptr);  // nothing sent yet
  line.push(5, 50);
  CHECK(line.take_newest_due(5).value == nullptr);
  CHECK(line.take_newest_due(7).value == nullptr);
  const auto first = line.take_newest_due(8);  // sent at 5, d = 3
  REQUIRE(first.value != nullptr);
  CHECK(*first.value == 50);
  CHECK(first.sequence == 1);
  // Asked again, the same value with the same sequence: a receiver can tell it has it already.
  CHECK(line.take_newest_due(8).sequence == 1);
  line.push(6, 60);
  line.push(7, 70);
  line.push(9, 90);
  CHECK(*line.take_newest_due(8).value == 50);  // 60 is due at 9, not before
  CHECK(*line.take_newest_due(9).value == 60);
  const auto newest = line.take_newest_due(11);  // 70 (due at 10) is passed over: 90 is not due until 12
  CHECK(*newest.value == 70);
  CHECK(newest.sequence == 3);
  CHECK(*line.take_newest_due(1000).value == 90);  // everything due: the newest
  CHECK(line.size() == 1);
  CHECK(line.dropped() == 0);

  SECTION("a delay of 0 hands a value over at the tick it was sent") {
    line.reset(0, 2);
    line.push(4, 40);
    CHECK(line.take_newest_due(3).value == nullptr);
    CHECK(*line.take_newest_due(4).value == 40);
  }
  SECTION("a full line drops its oldest value and counts it, without waiting or growing") {
    line.reset(10, 3);
    for (int k = 1; k <= 5; ++k) line.push(static_cast<std::uint64_t>(k), 10 * k);
    CHECK(line.dropped() == 2);
    CHECK(line.capacity() == 3);
    CHECK(*line.take_newest_due(13).value == 30);  // 10 and 20 were pushed out
  }
}

TEST_CASE("the in-process link delivers a frame sent at tick k at tick k + d, and the world reads the report of tick "
          "k - d") {
  for (const std::uint64_t delay : {0u, 1u, 7u, 23u}) {
    DYNAMIC_SECTION("d = " << delay) {
      constexpr std::uint64_t kTicksPerStep = 10;
      InProcessWorldLink link(lockstep_info(), InProcessLinkDelay{delay, kTicksPerStep});
      RecordingWorld world(link);
      link.connect(world);
      WorldLinkClient& haptic = link.attach(1);
      std::vector<std::uint64_t> step_ticks;
      std::vector<std::pair<std::uint64_t, std::uint64_t>> arrivals;  // (sent, taken) ticks of each frame
      // The master's order (HapticNode::lockstep_tick): report of tick k, the world's step if due, frames taken.
      for (std::uint64_t k = 1; k <= 120; ++k) {
        haptic.publish_report(report_of(k));
        if (k % kTicksPerStep == 3) {
          world.now_ticks = k;
          step_ticks.push_back(k);
          REQUIRE(haptic.step_world(k - 1));
        }
        PlaneFrame frame;
        if (haptic.receive_frame(0, frame)) arrivals.emplace_back(frame.frame_index, k);
      }
      // Every step's frame arrives exactly d ticks after it was sent, in order, none lost (a step every 10 ticks).
      std::vector<std::pair<std::uint64_t, std::uint64_t>> expected;
      for (const std::uint64_t sent : step_ticks) {
        if (sent + delay <= 120) expected.emplace_back(sent, sent + delay);
      }
      CHECK(arrivals == expected);
      // The world at tick k read the report of tick k − d, or none while k ≤ d.
      REQUIRE(world.read_ticks.size() == step_ticks.size());
      for (std::size_t i = 0; i < step_ticks.size(); ++i) {
        INFO("step at tick " << step_ticks[i]);
        CHECK(world.read_ticks[i] == (step_ticks[i] > delay ? step_ticks[i] - delay : 0));
      }
      CHECK(link.dropped() == 0);
    }
  }
}

TEST_CASE("with a delayed link a following controller takes its frames at its own tick k + d and the world reads each "
          "slot's report of tick k - d") {
  constexpr std::uint64_t kDelay = 4;
  constexpr std::uint64_t kTicksPerStep = 5;
  InProcessWorldLink link(lockstep_info(), InProcessLinkDelay{kDelay, kTicksPerStep});
  RecordingWorld world(link);
  link.connect(world);
  WorldLinkClient& master = link.attach(2);  // two fingers: slots 0 and 1
  WorldLinkClient& follower = link.attach(1);  // slot 2
  REQUIRE(follower.follower());
  std::vector<std::uint64_t> follower_arrivals;  // the follower's tick when each frame arrived, sent at tick ...
  std::vector<std::uint64_t> follower_sent;
  for (std::uint64_t k = 1; k <= 40; ++k) {
    master.publish_report(report_of(k, 0));
    master.publish_report(report_of(k, 1));
    // The follower's turn (HapticNode::follow_tick): frames first, as the end of its tick k − 1, then its report.
    PlaneFrame frame;
    if (follower.receive_frame(0, frame)) {
      CHECK(frame.endpoint == 2);
      follower_sent.push_back(frame.frame_index);
      follower_arrivals.push_back(k - 1);
    }
    follower.publish_report(report_of(k, 0));
    if (k % kTicksPerStep == 0) {
      world.now_ticks = k;
      REQUIRE(master.step_world(k - 1));
    }
    for (EndpointId finger = 0; finger < 2; ++finger) {
      if (master.receive_frame(finger, frame)) {
        CHECK(frame.endpoint == finger);
        CHECK(frame.frame_index + kDelay == k);
      }
    }
  }
  REQUIRE(follower_sent.size() >= 6);
  for (std::size_t i = 0; i < follower_sent.size(); ++i) CHECK(follower_arrivals[i] == follower_sent[i] + kDelay);
  // Steps at 5, 10, ..., 40, three slots each: none before tick 5 − 4 = 1, then the report of tick k − 4 in each.
  REQUIRE(world.read_ticks.size() == 8 * 3);
  for (std::size_t i = 0; i < world.read_ticks.size(); ++i) {
    CHECK(world.read_ticks[i] == 5 * (i / 3 + 1) - kDelay);
  }
  CHECK(link.dropped() == 0);
}

TEST_CASE("a delayed trial applies exactly the impulse rendered up to the report the world last read") {
  // The tap cut at 0.2 s, while the finger still pushes the cube: the last report the world read, that of tick
  // t_last − d, is behind the rendering, so the world has applied less than the haptic side rendered by the end.
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    for (const std::uint64_t phase : {0u, 29u}) {
      DYNAMIC_SECTION(to_string(coupling) << " coupling, phase " << phase) {
        constexpr std::uint64_t kDelay_ticks = 20;
        InProcessTrialOptions options = tap_options(coupling, phase, 0.020);
        options.duration_s = 0.2;
        options.out_dir =
            test::out_dir("link-delay-ledger-" + std::string(to_string(coupling)) + std::to_string(phase));
        const nlohmann::json summary = run_in_process_trial(options);
        CHECK(summary["link"]["delay_ticks"] == kDelay_ticks);
        CHECK(summary["link"]["dropped"] == 0);
        const std::uint64_t ticks = summary["haptic"]["ticks"].get<std::uint64_t>();
        REQUIRE(ticks == 200);
        // World step i at haptic tick i·50 + phase, after that tick's reports (HapticReport::tick = tick + 1); it read
        // the report of haptic tick t_last − d, whose totals are the log's row t_last − d.
        const std::uint64_t last_step_tick = phase + (ticks - 1 - phase) / 50 * 50;
        const auto rendered = rendered_by_tick(options.out_dir / "haptic.csv");
        REQUIRE(rendered.size() == ticks);
        const auto& read = rendered[last_step_tick - kDelay_ticks];
        const nlohmann::json& applied = summary["world"]["endpoints"][0]["impulse_by_object_Ns"]["0"];
        for (int axis = 0; axis < 3; ++axis) {
          INFO("axis " << axis << std::setprecision(17) << ": applied " << applied[axis].get<double>() << ", read "
                        << read[static_cast<std::size_t>(axis)]);
          // Equal to rounding: the world sums each report's difference of the running total, which telescopes to
          // the total exactly only in exact arithmetic; 200 reports of totals under 1 N·s round off at most
          // 200 · 2⁻⁵² N·s ≈ 4e-14 N·s.
          CHECK(applied[axis].get<double>() == Approx(read[static_cast<std::size_t>(axis)]).margin(1e-13));
        }
        // The cube was being pushed (a real impulse), and the haptic side had rendered more by the end.
        CHECK(read[0] > 0.02);
        CHECK(rendered.back()[0] > read[0] + 0.01);
        CHECK(summary["haptic"]["endpoints"][0]["impulse_by_object_Ns"]["0"][0].get<double>() == rendered.back()[0]);
      }
    }
  }
}

TEST_CASE("a whole delayed tap ends with the impulse applied equal to the impulse rendered") {
  // The finger leaves the cube 1.5 s before the end, so whatever the delay every report has reached the world.
  for (const double delay_s : {0.005, 0.1}) {
    DYNAMIC_SECTION("delay " << delay_s << " s") {
      const nlohmann::json summary = run_in_process_trial(tap_options(Coupling::impulse, 11, delay_s));
      const nlohmann::json& rendered = summary["haptic"]["endpoints"][0]["impulse_by_object_Ns"]["0"];
      const nlohmann::json& applied = summary["world"]["endpoints"][0]["impulse_by_object_Ns"]["0"];
      for (int axis = 0; axis < 3; ++axis) {
        CHECK(std::abs(rendered[axis].get<double>() - applied[axis].get<double>()) <=
              1e-12 * (1.0 + std::abs(rendered[axis].get<double>())));
      }
      CHECK(rendered[0].get<double>() > 0.1);
    }
  }
}

TEST_CASE("the servo measures the link's round trip, 2d in lockstep, which the world widens its reach by") {
  // A frame published at world step k·n applied the report of tick k·n − d and reaches the servo at tick k·n + d.
  for (const double delay_s : {0.0, 0.005, 0.1}) {
    DYNAMIC_SECTION("delay " << delay_s << " s") {
      const nlohmann::json summary = run_in_process_trial(tap_options(Coupling::local, 11, delay_s));
      CHECK(summary["haptic"]["endpoints"][0]["link_round_trip_s"].get<double>() ==
            Approx(2.0 * delay_s).margin(1e-12));
    }
  }
}

TEST_CASE("a link delay under half a tick is no delay: the trial is the undelayed one, bit for bit") {
  InProcessTrialOptions none = tap_options(Coupling::impulse, 17, 0.0);
  none.out_dir = test::out_dir("link-delay-none");
  InProcessTrialOptions tiny = tap_options(Coupling::impulse, 17, 0.0004);
  tiny.out_dir = test::out_dir("link-delay-tiny");
  const nlohmann::json a = run_in_process_trial(none);
  const nlohmann::json b = run_in_process_trial(tiny);
  CHECK(b["link"]["delay_ticks"] == 0);
  CHECK(a["objects"] == b["objects"]);
  for (const char* log : {"world.csv", "haptic.csv", "device.csv"}) {
    INFO(log);
    CHECK(test::read_text(none.out_dir / log) == test::read_text(tiny.out_dir / log));
  }
}

TEST_CASE("a delayed trial is bitwise repeatable and differs from the undelayed one") {
  InProcessTrialOptions first = tap_options(Coupling::position, 3, 0.037);
  first.out_dir = test::out_dir("link-delay-repeat-a");
  InProcessTrialOptions second = first;
  second.out_dir = test::out_dir("link-delay-repeat-b");
  const nlohmann::json a = run_in_process_trial(first);
  const nlohmann::json b = run_in_process_trial(second);
  CHECK(a["link"]["delay_ticks"] == 37);
  CHECK(a["objects"] == b["objects"]);
  for (const char* log : {"world.csv", "haptic.csv", "device.csv"}) {
    INFO(log);
    CHECK(test::read_text(first.out_dir / log) == test::read_text(second.out_dir / log));
  }
  const nlohmann::json undelayed = run_in_process_trial(tap_options(Coupling::position, 3, 0.0));
  CHECK(undelayed["objects"] != a["objects"]);
}

TEST_CASE("a link delay out of range is refused with the option, the value and the range") {
  for (const double bad : {-0.001, 1.5, std::nan("")}) {
    INFO(bad);
    try {
      run_in_process_trial(tap_options(Coupling::impulse, 0, bad));
      FAIL("accepted");
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      CHECK(message.find("link_delay_s") != std::string::npos);
      CHECK(message.find("between 0 and 1 s") != std::string::npos);
    }
  }
}

}  // namespace impetus
