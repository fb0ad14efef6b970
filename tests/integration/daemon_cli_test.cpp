#include "trial_support.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

namespace impetus {
namespace {

struct Result {
  int status;
  std::string output;
};

Result run(const std::string& command_line, const std::string& name) {
  const auto dir = test::out_dir(name);
  const auto output = dir / "output.txt";
  const int status = test::shell("cd '" + std::string(IMPETUS_SOURCE_DIR) + "' && timeout 20 " + command_line +
                                 " > '" + output.string() + "' 2>&1");
  return {status, test::read_text(output)};
}

bool segments_left(const std::string& shm) {
  return std::filesystem::exists("/dev/shm/" + shm + ".world") || std::filesystem::exists("/dev/shm/" + shm + ".device");
}

}  // namespace

TEST_CASE("every binary has --help") {
  for (const char* name : {"world_manager", "haptic_controller", "spidar_sim"}) {
    INFO(name);
    const Result result = run(test::binary(name) + " --help", std::string("help-") + name);
    CHECK(result.status == 0);
    CHECK_THAT(result.output, Catch::Contains("--shm"));
    CHECK_THAT(result.output, Catch::Contains("--clock"));
  }
}

TEST_CASE("bad flag values give a clear message, a non-zero exit and no segment left behind") {
  const std::string shm = "impetus_test_cli_" + std::to_string(getpid());
  const std::string world = test::binary("world_manager") + " --shm " + shm + " ";
  const std::string haptic = test::binary("haptic_controller") + " --shm " + shm + " --world-wait 0.2 ";
  const std::string device = test::binary("spidar_sim") + " --shm " + shm + " --attach-timeout 0.2 ";
  struct Case {
    std::string command;
    std::string expected;
  };
  const Case cases[] = {
      {world + "--scene scenes/tap.json --rate -5", "--rate"},
      {world + "--scene scenes/tap.json --coupling magnetic", "magnetic"},
      {world + "--scene scenes/missing.json", "missing.json"},
      {world + "--scene scenes/tap.json --log /nonexistent-dir/world.csv", "/nonexistent-dir"},
      {world + "--scene scenes/tap.json --clock sometimes", "sometimes"},
      {world + "--scene scenes/tap.json --clock lockstep --rate 300", "whole number of haptic ticks"},
      {world + "--scene scenes/tap.json --rate 1e300", "--rate"},
      {world + "--scene scenes/tap.json --duration nan", "finite"},
      {world + "--scene scenes/tap.json --log ''", "--log"},
      {haptic + "--rate nan", "--rate"},
      {haptic + "--world-wait nan", "finite"},
      {haptic + "--summary ''", "empty"},
      {device + "--trajectory tap --attach-timeout inf", "finite"},
      {haptic + "--rate 0", "--rate"},
      {haptic + "--device spidar:nosuchdevice.json", "nosuchdevice.json"},
      {haptic + "--device falcon", "falcon"},
      {haptic + "--stiffness -1", "--stiffness"},
      {haptic, "world link"},  // no world manager running
      {device + "--trajectory tap:speed=-1", "speed"},
      {device + "--trajectory nosuchfile.csv", "nosuchfile.csv"},
      {device + "--trajectory tap", "device port"},  // no haptic controller running
  };
  for (const Case& test_case : cases) {
    INFO(test_case.command);
    const Result result = run(test_case.command, "cli");
    INFO(result.output);
    CHECK(result.status != 0);
    CHECK(result.status != 124);  // not killed by the timeout: no hang
    CHECK_THAT(result.output, Catch::Contains(test_case.expected));
    CHECK_FALSE(segments_left(shm));
  }
}

TEST_CASE("a device started with another geometry than the haptic controller's is refused, naming both files") {
  const auto dir = test::out_dir("device-mismatch");
  const std::string shm = "impetus_test_mismatch_" + std::to_string(getpid());
  const std::string other = (dir / "wide_spidar.json").string();
  {
    std::ofstream file(other);
    file << R"({"frame_side_m": 0.6})";
  }
  const std::string shipped = std::string(IMPETUS_SOURCE_DIR) + "/common/spidar/desktop_spidar.json";
  const pid_t world = test::spawn({test::binary("world_manager"), "--scene", std::string(IMPETUS_SOURCE_DIR) +
                                   "/scenes/tap.json", "--clock", "lockstep", "--shm", shm}, dir / "world.out");
  const pid_t haptic = test::spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm,
                                    "--device", "spidar:" + shipped}, dir / "haptic.out");
  const Result device = run(test::binary("spidar_sim") + " --clock lockstep --shm " + shm +
                                " --attach-timeout 5 --trajectory tap --device spidar:" + other,
                            "device-mismatch-sim");
  kill(haptic, SIGTERM);
  kill(world, SIGTERM);
  CHECK(test::wait_for(haptic, 10) == 0);
  CHECK(test::wait_for(world, 10) == 0);
  INFO(device.output);
  CHECK(device.status == 1);
  CHECK_THAT(device.output, Catch::Contains("desktop_spidar.json"));
  CHECK_THAT(device.output, Catch::Contains("wide_spidar.json"));
  CHECK_FALSE(segments_left(shm));
}

}  // namespace impetus

namespace impetus {

TEST_CASE("a log or summary that cannot be written (a full disk) is reported and the exit status is non-zero") {
  // /dev/full accepts the open and fails every write with ENOSPC. Each daemon in turn writes there, in a lockstep
  // trial of the others.
  struct Case {
    std::string daemon;
    std::string flag;
  };
  const Case cases[] = {{"world_manager", "--log"}, {"haptic_controller", "--log"}, {"spidar_sim", "--log"},
                        {"haptic_controller", "--summary"}};
  for (const Case& c : cases) {
    INFO(c.daemon << " " << c.flag);
    const std::string name = "full-" + c.daemon + c.flag.substr(2);
    const auto dir = test::out_dir(name);
    const std::string shm = "impetus_test_full_" + std::to_string(getpid());
    auto extra = [&](const std::string& daemon) {
      return daemon == c.daemon ? std::vector<std::string>{c.flag, "/dev/full"} : std::vector<std::string>{};
    };
    auto command = [&](std::vector<std::string> argv, const std::string& daemon) {
      for (const std::string& arg : extra(daemon)) argv.push_back(arg);
      return argv;
    };
    const pid_t world = test::spawn(command({test::binary("world_manager"), "--scene", std::string(IMPETUS_SOURCE_DIR) +
                                             "/scenes/tap.json", "--clock", "lockstep", "--shm", shm}, "world_manager"),
                                    dir / "world.out");
    const pid_t haptic = test::spawn(command({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm},
                                             "haptic_controller"),
                                     dir / "haptic.out");
    const pid_t device = test::spawn(command({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm,
                                              "--attach-timeout", "5", "--trajectory", "tap"}, "spidar_sim"),
                                     dir / "device.out");
    const int device_status = test::wait_for(device, 30);
    kill(haptic, SIGTERM);
    const int haptic_status = test::wait_for(haptic, 10);
    kill(world, SIGTERM);
    const int world_status = test::wait_for(world, 10);
    const int status = c.daemon == "world_manager" ? world_status
                       : c.daemon == "haptic_controller" ? haptic_status
                                                         : device_status;
    const std::string out = test::read_text(dir / (c.daemon == "world_manager" ? "world.out"
                                                   : c.daemon == "haptic_controller" ? "haptic.out"
                                                                                      : "device.out"));
    INFO(out);
    CHECK(status != 0);
    CHECK(status != -1);  // exited by itself, not killed after a hang
    CHECK_THAT(out, Catch::Contains("/dev/full"));
    CHECK_FALSE(segments_left(shm));
  }
}

}  // namespace impetus

namespace impetus {

TEST_CASE("lockstep: when the haptic controller dies mid-trial, the world and the device say so and exit non-zero") {
  const auto dir = test::out_dir("lockstep-cut-short");
  const std::string shm = "impetus_test_cut_" + std::to_string(getpid());
  const pid_t world = test::spawn({test::binary("world_manager"), "--scene", std::string(IMPETUS_SOURCE_DIR) +
                                   "/scenes/tap.json", "--clock", "lockstep", "--shm", shm}, dir / "world.out");
  const pid_t haptic = test::spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm},
                                   dir / "haptic.out");
  // A 60 s press: far longer than the half second before the kill, whatever the machine's speed.
  const pid_t device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm,
                                    "--attach-timeout", "5", "--trajectory", "press:hold=60"}, dir / "device.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(haptic, SIGKILL);
  test::wait_for(haptic, 5);
  const int device_status = test::wait_for(device, 10);
  const int world_status = test::wait_for(world, 10);
  const std::string world_out = test::read_text(dir / "world.out");
  const std::string device_out = test::read_text(dir / "device.out");
  INFO(world_out);
  INFO(device_out);
  CHECK(world_status == 1);
  CHECK(device_status == 1);
  CHECK_THAT(world_out, Catch::Contains("went away mid-trial"));
  CHECK_THAT(device_out, Catch::Contains("went away mid-trajectory"));
  // The dead controller's device segment is its to remove; the survivors leave nothing of their own.
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".world"));
  std::filesystem::remove("/dev/shm/" + shm + ".device");
}

}  // namespace impetus

namespace impetus {

TEST_CASE("lockstep: a device killed mid-session is reported by the haptic controller, which then stops on SIGTERM") {
  const auto dir = test::out_dir("lockstep-device-killed");
  const std::string shm = "impetus_test_devkill_" + std::to_string(getpid());
  const pid_t world = test::spawn({test::binary("world_manager"), "--scene", std::string(IMPETUS_SOURCE_DIR) +
                                   "/scenes/tap.json", "--clock", "lockstep", "--shm", shm}, dir / "world.out");
  const pid_t haptic = test::spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm},
                                   dir / "haptic.out");
  const pid_t device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm,
                                    "--attach-timeout", "5", "--trajectory", "press:hold=60"}, dir / "device.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(device, SIGKILL);
  test::wait_for(device, 5);
  // The controller notices within its turn timeout and says so (it used to wait in silence).
  std::string haptic_out;
  for (int i = 0; i < 100 && haptic_out.find("went away mid-session") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    haptic_out = test::read_text(dir / "haptic.out");
  }
  INFO(haptic_out);
  CHECK_THAT(haptic_out, Catch::Contains("went away mid-session"));
  kill(haptic, SIGTERM);
  CHECK(test::wait_for(haptic, 10) != -1);  // it stops: no hang
  kill(world, SIGTERM);
  CHECK(test::wait_for(world, 10) != -1);
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".world"));
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".device"));
}

}  // namespace impetus
