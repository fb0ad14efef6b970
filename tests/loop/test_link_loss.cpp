// SPDX-License-Identifier: Apache-2.0
// Loss on the in-process world link (common/link/link_loss.h): the Gilbert–Elliott streams lose the fraction
// and the runs they are asked for, repeatably, and the impulse ledger stays exact through lost reports.

#include "common/link/inproc/inproc_world_link.h"
#include "common/link/link_loss.h"
#include "loop/in_process_trial.h"
#include "tests/integration/trial_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>

namespace impetus {
namespace {

struct Runs {
  double lost_fraction = 0.0;
  double mean_run = 0.0;
};

// Draws `packets` from a stream and measures the fraction lost and the mean run of consecutive losses.
Runs draw(const LinkLoss& loss, std::uint64_t stream, int packets) {
  LossProcess process(loss, stream);
  int lost = 0;
  int runs = 0;
  bool in_run = false;
  for (int k = 0; k < packets; ++k) {
    const bool gone = process.lose();
    lost += gone ? 1 : 0;
    if (gone && !in_run) ++runs;
    in_run = gone;
  }
  CHECK(process.lost() == static_cast<std::uint64_t>(lost));
  return {static_cast<double>(lost) / packets, runs > 0 ? static_cast<double>(lost) / runs : 0.0};
}

InProcessTrialOptions lossy_tap(Coupling coupling, double loss, double burst) {
  InProcessTrialOptions options;
  options.scene_path = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  options.trajectory = "tap";
  options.coupling = coupling;
  options.phase_ticks = 7;
  options.link_delay_s = 0.02;
  options.link_loss = loss;
  options.link_loss_burst = burst;
  return options;
}

}  // namespace

TEST_CASE("a loss stream loses the fraction and the runs it is asked for") {
  // 200 000 packets: the fraction's standard error is under 0.1 % of the packets, the runs' under 2 % of their mean.
  constexpr int kPackets = 200000;
  SECTION("independent losses: runs of 1/(1 − ℓ)") {
    const Runs runs = draw({0.2, 1.0, 5}, 0, kPackets);
    CHECK(runs.lost_fraction == Approx(0.2).margin(0.005));
    CHECK(runs.mean_run == Approx(1.25).epsilon(0.03));
  }
  SECTION("bursts: runs of B") {
    const Runs runs = draw({0.2, 5.0, 5}, 0, kPackets);
    CHECK(runs.lost_fraction == Approx(0.2).margin(0.01));
    CHECK(runs.mean_run == Approx(5.0).epsilon(0.05));
  }
  SECTION("no loss draws nothing and loses nothing") {
    const Runs runs = draw({0.0, 5.0, 5}, 0, 1000);
    CHECK(runs.lost_fraction == 0.0);
  }
  SECTION("the same seed and stream repeat; another stream does not") {
    LossProcess a({0.3, 2.0, 11}, 3);
    LossProcess b({0.3, 2.0, 11}, 3);
    LossProcess c({0.3, 2.0, 11}, 4);
    int same = 0;
    int differ = 0;
    for (int k = 0; k < 1000; ++k) {
      const bool x = a.lose();
      same += x == b.lose() ? 1 : 0;
      differ += x != c.lose() ? 1 : 0;
    }
    CHECK(same == 1000);
    CHECK(differ > 100);
  }
}

TEST_CASE("a lossy link loses frames and reports, the ledger stays exact, and the trial repeats bit for bit") {
  for (const Coupling coupling : {Coupling::impulse, Coupling::local}) {
    DYNAMIC_SECTION(to_string(coupling)) {
      InProcessTrialOptions first = lossy_tap(coupling, 0.2, 5.0);
      first.out_dir = test::out_dir(std::string("link-loss-a-") + to_string(coupling));
      InProcessTrialOptions second = first;
      second.out_dir = test::out_dir(std::string("link-loss-b-") + to_string(coupling));
      const nlohmann::json a = run_in_process_trial(first);
      const nlohmann::json b = run_in_process_trial(second);
      CHECK(a["link"]["lost_frames"].get<std::uint64_t>() > 0);
      CHECK(a["link"]["lost_reports"].get<std::uint64_t>() > 0);
      CHECK(a["link"]["loss"] == 0.2);
      for (const char* log : {"world.csv", "haptic.csv", "device.csv"}) {
        INFO(log);
        CHECK(test::read_text(first.out_dir / log) == test::read_text(second.out_dir / log));
      }
      // The finger leaves the cube long before the end: whatever was lost, the running totals brought it all.
      const nlohmann::json& rendered = a["haptic"]["endpoints"][0]["impulse_by_object_Ns"]["0"];
      const nlohmann::json& applied = a["world"]["endpoints"][0]["impulse_by_object_Ns"]["0"];
      for (int axis = 0; axis < 3; ++axis) {
        CHECK(std::abs(rendered[axis].get<double>() - applied[axis].get<double>()) <=
              1e-12 * (1.0 + std::abs(rendered[axis].get<double>())));
      }
      CHECK(rendered[0].get<double>() > 0.1);
      const nlohmann::json lossless = run_in_process_trial(lossy_tap(coupling, 0.0, 1.0));
      CHECK(lossless["link"]["lost_frames"] == 0);
      CHECK(lossless["link"]["lost_reports"] == 0);
    }
  }
}

TEST_CASE("link loss out of range is refused with the option, the value and the range") {
  for (const auto& [loss, burst, option] :
       {std::tuple{-0.1, 1.0, "link_loss"}, std::tuple{0.6, 1.0, "link_loss"}, std::tuple{std::nan(""), 1.0, "link_loss"},
        std::tuple{0.1, 0.5, "link_loss_burst"}, std::tuple{0.1, 2000.0, "link_loss_burst"}}) {
    INFO(option << " " << loss << " " << burst);
    try {
      run_in_process_trial(lossy_tap(Coupling::impulse, loss, burst));
      FAIL("accepted");
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      CHECK(message.find(option) != std::string::npos);
      CHECK(message.find("must be between") != std::string::npos);
    }
  }
}

}  // namespace impetus

namespace impetus {

TEST_CASE("over a lossy link the world reads the newest report that arrived, and a node keeps its last frame") {
  WorldLinkInfo info;
  info.world_rate_hz = 100.0;
  info.world_period_s = 0.01;
  info.clock = ClockMode::lockstep;
  InProcessWorldLink link(info, InProcessLinkDelay{0, 10}, LinkLoss{0.5, 3.0, 9});
  WorldLinkClient& client = link.attach();
  std::vector<std::uint64_t> read_ticks;
  std::vector<std::uint64_t> frames_taken;
  for (std::uint64_t tick = 1; tick <= 2000; ++tick) {
    HapticReport report;
    report.tick = tick;
    report.haptic_session = 1;
    client.publish_report(report);
    if (tick % 10 == 0) {
      HapticReport read;
      read_ticks.push_back(link.latest_report(0, read) ? read.tick : 0);
      PlaneFrame frame;
      frame.frame_index = tick;
      link.publish_frame(0, frame);
    }
    PlaneFrame taken;
    if (client.receive_frame(0, taken)) frames_taken.push_back(taken.frame_index);
  }
  // Reports: about half of those the world would have read are lost, and then it reads an older one, never a newer.
  std::size_t older = 0;
  for (std::size_t k = 0; k < read_ticks.size(); ++k) {
    const std::uint64_t step_tick = 10 * (k + 1);
    CHECK(read_ticks[k] <= step_tick);
    older += read_ticks[k] < step_tick ? 1 : 0;
  }
  CHECK(older > read_ticks.size() / 4);
  CHECK(older < 3 * read_ticks.size() / 4);
  // Frames: only those not lost arrive, each once, in order.
  CHECK(frames_taken.size() + link.lost_frames() == read_ticks.size());
  CHECK(link.lost_frames() > read_ticks.size() / 4);
  CHECK(link.lost_reports() > 500);
}

}  // namespace impetus
