// SPDX-License-Identifier: Apache-2.0
// The daemons over the DDS world link on this host (real sockets between processes; tests/dds/netns_test.sh puts them
// on two network hosts). Real time, so no timing is asserted: the ledger, the slots and the absence of bursts are.
// Each test meets in a DDS partition of its own.

#include "csv_columns.h"
#include "common/link/shm/names.h"
#include "trial_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>

namespace impetus {
namespace {

struct DdsDaemons {
  std::filesystem::path dir;
  std::string partition;
  std::string scene = std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json";
  std::string coupling = "impulse";

  std::vector<std::string> link() const { return {"--clock", "realtime", "--link", "dds", "--dds-partition", partition}; }
  std::string shm(const std::string& tag) const { return partition + "_" + tag; }

  pid_t world(const std::string& tag) const {
    std::vector<std::string> argv{test::binary("world_manager"), "--scene", scene, "--coupling", coupling, "--shm",
                                  shm("world" + tag), "--log", (dir / ("world" + tag + ".csv")).string(),
                                  "--summary", (dir / ("world" + tag + ".json")).string()};
    for (const auto& arg : link()) argv.push_back(arg);
    return test::spawn(argv, dir / ("world" + tag + ".out"));
  }
  // A controller with its device port on "<partition>_<user>"; its logs are haptic<tag>.*.
  pid_t haptic(const std::string& user, const std::string& tag) const {
    std::vector<std::string> argv{test::binary("haptic_controller"), "--shm", shm(user), "--log",
                                  (dir / ("haptic" + tag + ".csv")).string(), "--summary",
                                  (dir / ("haptic" + tag + ".json")).string()};
    for (const auto& arg : link()) argv.push_back(arg);
    return test::spawn(argv, dir / ("haptic" + tag + ".out"));
  }
  pid_t device(const std::string& user, const std::string& tag, const std::string& trajectory) const {
    return test::spawn({test::binary("spidar_sim"), "--clock", "realtime", "--shm", shm(user), "--trajectory",
                        trajectory, "--attach-timeout", "30"},
                       dir / ("device" + tag + ".out"));
  }
};

DdsDaemons make_daemons(const std::string& name) {
  DdsDaemons daemons;
  daemons.dir = test::out_dir("dds-" + name);
  daemons.partition = "impetus_test_" + name + "_" + std::to_string(getpid());
  return daemons;
}

void stop(pid_t pid) {
  kill(pid, SIGTERM);
  CHECK(test::wait_for(pid, 15.0) == 0);
}

void sleep_s(double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); }

// Cyclone's own loss injection (a configuration for tests): this fraction of every packet the process sends is
// dropped, discovery and retransmissions included. Set for the processes started while it lives.
class PacketLoss {
 public:
  explicit PacketLoss(int per_mille) {
    if (per_mille > 0) {
      const std::string config =
          "<Internal><Test><XmitLossiness>" + std::to_string(per_mille) + "</XmitLossiness></Test></Internal>";
      setenv("CYCLONEDDS_URI", config.c_str(), 1);
    }
  }
  ~PacketLoss() { unsetenv("CYCLONEDDS_URI"); }
};

double fastest_mps(const std::filesystem::path& world_csv, const std::string& object) {
  const auto log = test::read_csv_columns(world_csv);
  double fastest = 0.0;
  for (std::size_t i = 0; i < log.at(object + ".vx_mps").size(); ++i) {
    fastest = std::max(fastest, std::hypot(log.at(object + ".vx_mps")[i], log.at(object + ".vy_mps")[i],
                                           log.at(object + ".vz_mps")[i]));
  }
  return fastest;
}

// The world's ledger entry for controller session `session`, endpoint 0, object 0.
nlohmann::json applied_for(const nlohmann::json& world_summary, const nlohmann::json& session) {
  for (const auto& entry : world_summary["world"]["endpoints"]) {
    if (entry["haptic_session"] == session && entry["endpoint"] == 0) return entry["impulse_by_object_Ns"]["0"];
  }
  return nullptr;
}

}  // namespace

TEST_CASE("over DDS the world applies exactly the impulse the controller rendered, at 0, 1 and 10 % packet loss") {
  for (const int loss_per_mille : {0, 10, 100}) {
    INFO("packet loss " << loss_per_mille << " per mille");
    const DdsDaemons daemons = make_daemons("loss" + std::to_string(loss_per_mille));
    const PacketLoss loss(loss_per_mille);
    const pid_t world = daemons.world("");
    const pid_t haptic = daemons.haptic("u", "");
    const pid_t device = daemons.device("u", "", "tap");
    CHECK(test::wait_for(device, 60.0) == 0);
    stop(haptic);
    stop(world);
    INFO(test::read_text(daemons.dir / "haptic.out") << test::read_text(daemons.dir / "world.out"));

    const auto haptic_summary = test::read_json(daemons.dir / "haptic.json")["haptic"];
    const auto world_summary = test::read_json(daemons.dir / "world.json");
    const auto& rendered = haptic_summary["impulse_by_object_Ns"]["0"];
    const auto& applied = world_summary["objects"]["cube"]["impulse_Ns"];
    REQUIRE(rendered.is_array());
    CHECK(rendered[0].get<double>() > 0.3);  // the tap happened (about 0.6 N·s along +x)
    for (int a = 0; a < 3; ++a) {
      // Running totals: whatever was lost on the way, the last report the world took carries the whole sum.
      CHECK(applied[a].get<double>() == Approx(rendered[a].get<double>()).epsilon(1e-12).margin(1e-15));
    }
    CHECK(haptic_summary["faults"] == 0);
    CHECK(haptic_summary["rejected_frames"] == 0);
    CHECK(world_summary["world"]["rejected_reports"] == 0);
    CHECK(world_summary["world"]["dds"]["refused_endpoints"] == 0);
  }
}

TEST_CASE("over DDS a controller serves one world: a second live world on its partition is reported, not adopted") {
  const DdsDaemons daemons = make_daemons("twoworlds");
  const pid_t first = daemons.world("1");
  const pid_t haptic = daemons.haptic("u", "");
  sleep_s(1.0);  // the controller follows the first world
  const pid_t second = daemons.world("2");
  const pid_t device = daemons.device("u", "", "tap");
  CHECK(test::wait_for(device, 60.0) == 0);
  stop(haptic);
  stop(first);
  stop(second);
  INFO(test::read_text(daemons.dir / "haptic.out") << test::read_text(daemons.dir / "world2.out"));

  const auto haptic_summary = test::read_json(daemons.dir / "haptic.json");
  CHECK(haptic_summary["haptic"]["world_attaches"] == 1);  // never switched
  CHECK(haptic_summary["haptic"]["dds"]["other_worlds"].get<int>() >= 1);
  CHECK_THAT(test::read_text(daemons.dir / "haptic.out"), Catch::Contains("another world manager"));
  // The tap's whole impulse landed in the followed world, exactly once; none in the other.
  const auto& rendered = haptic_summary["haptic"]["impulse_by_object_Ns"]["0"];
  const auto followed = test::read_json(daemons.dir / "world1.json");
  const auto other = test::read_json(daemons.dir / "world2.json");
  REQUIRE(rendered.is_array());
  CHECK(rendered[0].get<double>() > 0.3);
  for (int a = 0; a < 3; ++a) {
    CHECK(followed["objects"]["cube"]["impulse_Ns"][a].get<double>() ==
          Approx(rendered[a].get<double>()).epsilon(1e-12).margin(1e-15));
    CHECK(other["objects"]["cube"]["impulse_Ns"][a].get<double>() == 0.0);
  }
  // No check of the largest force: in real time on a loaded machine late frames alone can take a tap to the clamp
  // (seen twice with two test runs sharing 2 cores), so it would not tell whether the other world's planes reached
  // the servo; the attach count and the two ledgers above do.
}

TEST_CASE("over DDS a world killed mid-press is followed to its restart, which applies only what came after") {
  DdsDaemons daemons = make_daemons("restart");
  daemons.coupling = "local";
  pid_t world = daemons.world("1");
  const pid_t haptic = daemons.haptic("u", "");
  const pid_t device = daemons.device("u", "", "press:x=0.03,surface_z=0.05,depth=0.01,hold=5");
  sleep_s(2.5);  // the press reaches the cube after ~0.4 s of its motion (which starts once the world served it)
  kill(world, SIGKILL);
  CHECK(test::wait_for(world, 5.0) == -1);
  sleep_s(0.5);
  world = daemons.world("2");
  CHECK(test::wait_for(device, 60.0) == 0);
  stop(haptic);
  stop(world);
  // A world killed with SIGKILL cannot remove its view segment; the next world on its --shm takes it over. This
  // restart ran under another name, so the killed one's is removed here (segment.h: a stale segment is ours to remove).
  std::filesystem::remove("/dev/shm/" + world_view_name(daemons.shm("world1")));
  INFO(test::read_text(daemons.dir / "haptic.out") << test::read_text(daemons.dir / "world2.out"));

  const auto haptic_summary = test::read_json(daemons.dir / "haptic.json")["haptic"];
  CHECK(haptic_summary["world_attaches"] == 2);
  CHECK(haptic_summary["faults"] == 0);
  CHECK(haptic_summary["stale_world_ticks"].get<int>() > 0);  // the planes were held while no world answered
  const auto second = test::read_json(daemons.dir / "world2.json");
  CHECK(second["objects"]["cube"]["impulse_Ns"][2].get<double>() < -0.1);  // the finger went on pressing it
  // What was rendered against the first world is not applied to the second: its cube, pressed onto the floor, never
  // moves faster than a hand could push it.
  const double fastest = fastest_mps(daemons.dir / "world2.csv", "cube");
  INFO("fastest cube in the restarted world " << fastest << " m/s");
  CHECK(fastest < 0.1);
}

TEST_CASE("over DDS one world serves four controllers, and one killed with kill -9 frees its slot and its restart is "
          "served with no burst") {
  const DdsDaemons daemons = make_daemons("four");
  const std::vector<std::string> users{"a", "b", "c", "d"};
  // Four fingers press the cube's top (z = 0.05 m, 5 cm square around x = 0.03) near its four corners.
  const double xs[] = {0.015, 0.045, 0.015, 0.045}, ys[] = {-0.012, -0.012, 0.012, 0.012};
  const pid_t world = daemons.world("");
  std::vector<pid_t> haptics, devices;
  for (std::size_t u = 0; u < users.size(); ++u) {
    const std::string press = "press:x=" + std::to_string(xs[u]) + ",y=" + std::to_string(ys[u]) +
                              ",surface_z=0.05,depth=0.01,hold=6";
    haptics.push_back(daemons.haptic(users[u], users[u]));
    devices.push_back(daemons.device(users[u], users[u], press));
  }
  sleep_s(3.0);
  kill(haptics[3], SIGKILL);  // user d leaves without a goodbye
  CHECK(test::wait_for(haptics[3], 5.0) == -1);
  CHECK(test::wait_for(devices[3], 10.0) >= 0);  // its device saw its host die
  sleep_s(0.5);
  const pid_t restarted = daemons.haptic("d", "d2");
  const pid_t restarted_device =
      daemons.device("d", "d2", "press:x=0.045,y=0.012,surface_z=0.05,depth=0.01,hold=2");
  for (int u = 0; u < 3; ++u) CHECK(test::wait_for(devices[u], 60.0) == 0);
  CHECK(test::wait_for(restarted_device, 60.0) == 0);
  // By now the killed controller has been silent for longer than the DDS lease: the world freed its slot.
  const std::string world_out = test::read_text(daemons.dir / "world.out");
  INFO(world_out);
  CHECK(world_out.find("is free again") != std::string::npos);
  for (int u = 0; u < 3; ++u) stop(haptics[u]);
  stop(restarted);
  stop(world);

  const auto world_summary = test::read_json(daemons.dir / "world.json");
  CHECK(world_summary["world"]["dds"]["refused_endpoints"] == 0);
  for (const std::string tag : {"a", "b", "c", "d2"}) {
    INFO("controller " << tag);
    const auto haptic_summary = test::read_json(daemons.dir / ("haptic" + tag + ".json"))["haptic"];
    CHECK(haptic_summary["faults"] == 0);
    const auto& rendered = haptic_summary["impulse_by_object_Ns"]["0"];
    REQUIRE(rendered.is_array());
    CHECK(rendered[2].get<double>() < -0.1);  // it pressed
    const auto applied = applied_for(world_summary, haptic_summary["endpoints"][0]["haptic_session"]);
    REQUIRE(applied.is_array());
    for (int a = 0; a < 3; ++a) {
      CHECK(applied[a].get<double>() == Approx(rendered[a].get<double>()).epsilon(1e-12).margin(1e-15));
    }
  }
  const double fastest = fastest_mps(daemons.dir / "world.csv", "cube");
  INFO("fastest cube " << fastest << " m/s");
  CHECK(fastest < 0.1);  // pressed onto the floor from above by four fingers: it never moves much
}

}  // namespace impetus
