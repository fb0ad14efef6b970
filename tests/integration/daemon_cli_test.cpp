#include "trial_support.h"

#include <catch2/catch.hpp>

#include <filesystem>

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
      {haptic + "--rate 0", "--rate"},
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

}  // namespace impetus
