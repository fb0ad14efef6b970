// SPDX-License-Identifier: Apache-2.0
#include "trial_support.h"

#include "common/link/shm/world_link_layout.h"

#include <catch2/catch.hpp>

#include <sys/mman.h>

#include <cstddef>
#include <cstring>
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
  return std::filesystem::exists("/dev/shm/" + shm + ".world") || std::filesystem::exists("/dev/shm/" + shm + ".device") ||
         std::filesystem::exists("/dev/shm/" + shm + ".view");
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

TEST_CASE("every binary has --version, bad usage exits 2 and bad input 1") {
  for (const char* name : {"world_manager", "haptic_controller", "spidar_sim", "viewer"}) {
    INFO(name);
    const Result version = run(test::binary(name) + " --version", std::string("version-") + name);
    CHECK(version.status == 0);
    CHECK_THAT(version.output, Catch::StartsWith(std::string(name) + " ") && Catch::Contains("."));
    const std::string required = std::string(name) == "world_manager" ? " --scene scenes/tap.json" : "";
    const Result unknown = run(test::binary(name) + required + " --no-such-flag", std::string("usage-") + name);
    CHECK(unknown.status == 2);
    CHECK_THAT(unknown.output, Catch::Contains("--no-such-flag"));
  }
  CHECK(run(test::binary("world_manager") + " --scene scenes/tap.json --coupling spring", "usage-enum").status == 2);
  CHECK(run(test::binary("world_manager") + " --scene scenes/tap.json --check-flags", "check-flags").status == 0);
  // A file that exists but cannot be used is bad input.
  const auto bad_scene = test::out_dir("bad-input-scene") / "bad_scene.json";
  std::ofstream(bad_scene) << R"({"objects": [{"name": "c", "shape": "cube"}]})";
  const Result bad_input = run(test::binary("world_manager") + " --scene " + bad_scene.string() +
                                   " --shm impetus_test_bad_" + std::to_string(getpid()),
                               "bad-input");
  CHECK(bad_input.status == 1);
  CHECK_THAT(bad_input.output, Catch::Contains("bad_scene.json") && Catch::Contains("cube"));
}

TEST_CASE("a script's --help prints and does nothing else, and run.sh checks every flag before starting anything") {
  namespace fs = std::filesystem;
  const fs::path source(IMPETUS_SOURCE_DIR);
  // demo.sh --help used to delete out/demo; make_figures.sh --help regenerated the tracked figures; build.sh --help
  // handed --help to cmake as a directory.
  const fs::path marker = source / "out" / "demo" / "kept-by-help";
  fs::create_directories(marker.parent_path());
  std::ofstream(marker) << "a trial's output\n";
  const auto figure_time = fs::last_write_time(source / "docs" / "phase.md");
  for (const char* script : {"demo.sh", "build.sh", "deps.sh", "fuzz.sh", "make_figures.sh", "run.sh", "bench.sh",
                             "test.sh", "dds_security.sh"}) {
    INFO(script);
    const Result help = run(std::string("bash scripts/") + script + " --help", std::string("script-help-") + script);
    CHECK(help.status == 0);
    CHECK(help.output.size() > 40);
  }
  CHECK(fs::exists(marker));
  fs::remove(marker);
  CHECK(fs::last_write_time(source / "docs" / "phase.md") == figure_time);
  CHECK_FALSE(fs::exists(source / "--help"));
  for (const char* script : {"deps.sh", "make_figures.sh", "build.sh"}) {
    INFO(script);
    CHECK(run(std::string("bash scripts/") + script + " --bogus", std::string("script-bad-") + script).status == 2);
  }
  // A bad value: one message and status 2, and no daemon started (no summary, no segment).
  const auto dir = test::out_dir("run-bad-coupling");
  const Result bad = run("bash scripts/run.sh --scene scenes/tap.json --trajectory tap --coupling spring --out " +
                             (dir / "trial").string(),
                         "run-bad-coupling-output");
  CHECK(bad.status == 2);
  CHECK_THAT(bad.output, Catch::Contains("run.sh: world_manager") && Catch::Contains("spring"));
  CHECK_FALSE(fs::exists(dir / "trial" / "world.json"));
  CHECK_FALSE(fs::exists(dir / "trial" / "haptic.json"));
}

TEST_CASE("bad flag values give a clear message, a non-zero exit and no segment left behind") {
  const std::string shm = "impetus_test_cli_" + std::to_string(getpid());
  const std::string world = test::binary("world_manager") + " --shm " + shm + " ";
  const std::string haptic = test::binary("haptic_controller") + " --shm " + shm + " --world-wait 0.2 ";
  const std::string device = test::binary("spidar_sim") + " --shm " + shm + " --attach-timeout 0.2 ";
  const auto far_csv = test::out_dir("cli-far") / "far.csv";  // a finger 5 m out of the 0.4 m frame
  std::ofstream(far_csv) << "t,x,y,z\n0,0,0,0.05\n1,5,0,0.05\n";
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
      {device + "--trajectory " + far_csv.string(), "outside the device's frame"},
      {device + "--trajectory tap", "device port"},  // no haptic controller running
      // A phase is an offset within one world period; 2^64 must not saturate into a valid-looking value.
      {world + "--scene scenes/tap.json --clock lockstep --phase 50", "the phase must be 0 to 49"},
      {world + "--scene scenes/tap.json --clock lockstep --phase 18446744073709551616", "whole number from 0"},
      // Readable bounds (CLI11's printed 309 digits) and the real reason.
      {haptic + "--rate 1e300", "between 100 and 20000"},
      {device + "--trajectory tap --finger-mass -1", "must be positive, not -1"},
      {haptic + "--stiffness 1e12", "at most 1e+06"},
      {world + "--scene scenes/tap.json --substeps 99999999999999999999", "whole number from 1 to 10000"},
      // The world link's transport: DDS is real time only, and a controller names where it looked.
      {world + "--scene scenes/tap.json --link carrier-pigeon", "carrier-pigeon"},
      // Segment names: never hidden files, never a path.
      {test::binary("world_manager") + " --scene scenes/tap.json --shm ''", "--shm: must not be empty"},
      {test::binary("world_manager") + " --scene scenes/tap.json --shm .hidden", "must not start with '.'"},
      {test::binary("haptic_controller") + " --shm a/b", "may hold only letters"},
      {world + "--scene scenes/tap.json --link dds --clock lockstep", "real time only"},
      {world + "--scene scenes/tap.json --link dds --dds-domain 233", "from 0 to 232, not 233"},
      {world + "--scene scenes/tap.json --link dds --dds-partition ''", "must not be empty"},
      {haptic + "--link dds --clock lockstep", "real time only"},
      {haptic + "--clock realtime --link dds --world-shm elsewhere", "--world-shm names a shared-memory world link"},
      // A tool in the hand: the scene must have one, and a grip holds it; the grip's hand has no finger's flags.
      {haptic + "--device grip --tool-from scenes/tap.json", "has no \"tool\" block"},
      {haptic + "--device grip --tool-from scenes/missing.json", "missing.json"},
      {haptic + "--device grip:nosuchgrip.json", "nosuchgrip.json"},
      {device + "--device grip --trajectory tap --finger-mass 0.2", "--finger-mass is not for --device grip"},
      {device + "--device grip --trajectory " + far_csv.string(), "frame"},
      {haptic + "--clock realtime --link dds --dds-partition impetus_test_nobody_" + std::to_string(getpid()),
       "no world manager answered on DDS domain 0 partition 'impetus_test_nobody_"},
  };
  for (const Case& test_case : cases) {
    INFO(test_case.command);
    const Result result = run(test_case.command, "cli");
    INFO(result.output);
    CHECK(result.status != 0);
    CHECK(result.status != 124);  // not killed by the timeout: no hang
    CHECK_THAT(result.output, Catch::Contains(test_case.expected));
    CHECK(result.output.size() < 600);  // a short message, no 309-digit bounds
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
  // An hour's press: lockstep runs the tap scene at up to ~120x real time here (a 60 s press once ended within the
  // half second before the kill), so the kill lands mid-trial on any machine short of ~7000x.
  const pid_t device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm,
                                    "--attach-timeout", "5", "--trajectory", "press:hold=3600"}, dir / "device.out");
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
  // An hour's press, for the same reason as above: the kill must land mid-session.
  const pid_t device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm,
                                    "--attach-timeout", "5", "--trajectory", "press:hold=3600"}, dir / "device.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(device, SIGKILL);
  test::wait_for(device, 5);
  // The controller notices within its turn timeout and says so (it used to wait in silence).
  std::string haptic_out;
  for (int i = 0; i < 100 && haptic_out.find("is lost mid-session") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    haptic_out = test::read_text(dir / "haptic.out");
  }
  INFO(haptic_out);
  CHECK_THAT(haptic_out, Catch::Contains("is lost mid-session"));
  kill(haptic, SIGTERM);
  CHECK(test::wait_for(haptic, 10) == 1);  // it stops (no hang), and the cut-short trial is not a success
  kill(world, SIGTERM);
  CHECK(test::wait_for(world, 10) != -1);
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".world"));
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".device"));
  CHECK_FALSE(std::filesystem::exists("/dev/shm/" + shm + ".view"));
}

}  // namespace impetus

namespace impetus {
namespace {

// The three daemons of a lockstep trial that would run for minutes: a 600 s press.
struct LongLockstepTrial {
  std::filesystem::path dir;
  std::string shm;
  pid_t world, haptic, device;

  // The world and the haptic controller write world.json and haptic.json into `dir` when they exit.
  explicit LongLockstepTrial(const std::string& name)
      : dir(test::out_dir(name)), shm("impetus_test_" + name + "_" + std::to_string(getpid())) {
    world = test::spawn({test::binary("world_manager"), "--scene", std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json",
                         "--clock", "lockstep", "--shm", shm, "--summary", (dir / "world.json").string()},
                        dir / "world.out");
    haptic = test::spawn({test::binary("haptic_controller"), "--clock", "lockstep", "--shm", shm, "--summary",
                          (dir / "haptic.json").string()}, dir / "haptic.out");
    device = test::spawn({test::binary("spidar_sim"), "--clock", "lockstep", "--shm", shm, "--attach-timeout", "5",
                          "--trajectory", "press:hold=600"}, dir / "device.out");
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  std::string output(const char* who) const { return test::read_text(dir / (std::string(who) + ".out")); }
  bool segments_left() const {
    return std::filesystem::exists("/dev/shm/" + shm + ".world") ||
           std::filesystem::exists("/dev/shm/" + shm + ".device") || std::filesystem::exists("/dev/shm/" + shm + ".view");
  }
};

// A trial's world link mapped read-write, as another process could map it to scribble on it.
class MappedWorldLink {
 public:
  explicit MappedWorldLink(const std::string& shm) {
    const int fd = ::open(("/dev/shm/" + shm + ".world").c_str(), O_RDWR);
    if (fd >= 0) {
      mapping_ = mmap(nullptr, sizeof(WorldLinkLayout), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
      ::close(fd);
    }
  }
  ~MappedWorldLink() {
    if (mapped()) munmap(mapping_, sizeof(WorldLinkLayout));
  }
  bool mapped() const { return mapping_ != MAP_FAILED; }
  WorldLinkLayout& layout() const { return *static_cast<WorldLinkLayout*>(mapping_); }

 private:
  void* mapping_ = MAP_FAILED;
};

}  // namespace

TEST_CASE("lockstep: a stop request ends a running trial at once and cleanly, whichever process gets it") {
  // Turns keep coming in lockstep, so a follower never waited long enough to look at its stop flag, and the master
  // never looked at it at all: SIGINT (Ctrl-C) and SIGTERM were ignored until the trajectory ended.
  SECTION("SIGINT to all three, as Ctrl-C in a terminal sends it") {
    LongLockstepTrial trial("stop-all");
    const auto start = std::chrono::steady_clock::now();
    for (pid_t pid : {trial.world, trial.haptic, trial.device}) kill(pid, SIGINT);
    CHECK(test::wait_for(trial.haptic, 10) == 0);
    CHECK(test::wait_for(trial.world, 10) == 0);
    CHECK(test::wait_for(trial.device, 10) == 0);
    std::printf("lockstep stop, SIGINT to all: %.0f ms until all three exited\n",
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    CHECK_FALSE(trial.segments_left());
  }
  SECTION("SIGTERM to the haptic controller, the master clock: it ends the session for the others") {
    LongLockstepTrial trial("stop-master");
    kill(trial.haptic, SIGTERM);
    CHECK(test::wait_for(trial.haptic, 10) == 0);
    CHECK(test::wait_for(trial.world, 10) == 0);
    CHECK(test::wait_for(trial.device, 10) == 0);
    CHECK_THAT(trial.output("device"), Catch::Contains("ended the session"));
    CHECK_FALSE(trial.segments_left());
  }
  SECTION("SIGTERM to the device: it detaches cleanly, and the controller is not told a device died") {
    LongLockstepTrial trial("stop-device");
    kill(trial.device, SIGTERM);
    CHECK(test::wait_for(trial.device, 10) == 0);
    kill(trial.haptic, SIGTERM);
    CHECK(test::wait_for(trial.haptic, 10) == 0);
    kill(trial.world, SIGTERM);
    CHECK(test::wait_for(trial.world, 10) == 0);
    CHECK_THAT(trial.output("device"), Catch::Contains("stopped"));
    CHECK_THAT(trial.output("haptic"), !Catch::Contains("is lost"));
    CHECK_FALSE(trial.segments_left());
  }
}

TEST_CASE("lockstep: the haptic controller exits non-zero when the world dies mid-trial") {
  LongLockstepTrial trial("world-killed");
  kill(trial.world, SIGKILL);
  test::wait_for(trial.world, 5);
  kill(trial.device, SIGTERM);
  CHECK(test::wait_for(trial.device, 10) == 0);
  kill(trial.haptic, SIGTERM);
  CHECK(test::wait_for(trial.haptic, 10) == 1);
  const std::string haptic_out = trial.output("haptic");
  INFO(haptic_out);
  CHECK_THAT(haptic_out, Catch::Contains("the trial is incomplete") && Catch::Contains("world manager"));
  std::filesystem::remove("/dev/shm/" + trial.shm + ".world");  // the killed world's own segments
  std::filesystem::remove("/dev/shm/" + trial.shm + ".view");
  CHECK_FALSE(trial.segments_left());
}

TEST_CASE("run.sh stops a lockstep trial on SIGINT and leaves nothing behind") {
  const auto dir = test::out_dir("run-interrupted");
  const pid_t run = test::spawn({"/bin/bash", std::string(IMPETUS_SOURCE_DIR) + "/scripts/run.sh", "--scene",
                                 std::string(IMPETUS_SOURCE_DIR) + "/scenes/tap.json", "--clock", "lockstep",
                                 "--trajectory", "press:hold=600", "--duration", "700", "--out",
                                 (dir / "trial").string(), "--quiet"},
                                dir / "run.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  REQUIRE(waitpid(run, nullptr, WNOHANG) == 0);  // still running: a 600 s press
  kill(run, SIGINT);
  CHECK(test::wait_for(run, 15) == 130);
  CHECK_THAT(test::read_text(dir / "run.out"), Catch::Contains("interrupted"));
}

}  // namespace impetus

namespace impetus {

TEST_CASE("lockstep: a turn scribbled by another process ends the trial with a message, no abort, no segment left") {
  LongLockstepTrial trial("scribbled-turn");
  // Another process (here the test) writes garbage over the world link's turn while the trial runs.
  {
    const MappedWorldLink link(trial.shm);
    REQUIRE(link.mapped());
    std::memset(static_cast<void*>(&link.layout().world_turn), 0xAB, sizeof(LockstepTurn));
  }
  // The world and the controller each find the corrupted turn and say so; neither aborts (status -1: a signal).
  CHECK(test::wait_for(trial.world, 10) == 1);
  kill(trial.device, SIGTERM);
  CHECK(test::wait_for(trial.device, 10) == 0);
  kill(trial.haptic, SIGTERM);
  CHECK(test::wait_for(trial.haptic, 10) == 1);
  INFO(trial.output("world"));
  INFO(trial.output("haptic"));
  CHECK_THAT(trial.output("world"), Catch::Contains("corrupted"));
  CHECK_THAT(trial.output("haptic"), Catch::Contains("the trial is incomplete"));
  CHECK_FALSE(trial.segments_left());
}

}  // namespace impetus

namespace impetus {

TEST_CASE("lockstep: odd sequence words scribbled into the running link are repaired and counted, the trial goes on") {
  LongLockstepTrial trial("scribbled-sequence");
  const auto& dir = trial.dir;
  const MappedWorldLink link(trial.shm);
  REQUIRE(link.mapped());
  auto& layout = link.layout();
  // The sequence word is each channel's first; an odd value at rest made every reader wait for a write that never
  // ends. A scribble that lands while the writer is mid-write is overwritten by that write, so it is done 20 times.
  const std::uint64_t before = layout.slots[0].report.sequence();
  for (int i = 0; i < 20; ++i) {
    reinterpret_cast<std::atomic<std::uint64_t>*>(&layout.slots[0].planes)->store(1001);
    reinterpret_cast<std::atomic<std::uint64_t>*>(&layout.slots[0].report)->store(2001);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // Still moving: the report's sequence word is at rest (even) again, at a value it did not have before. One sample
  // may land inside a write (odd; a report is written every tick), so it is sampled for up to 100 ms.
  bool still_moving = false;
  for (int i = 0; i < 100 && !still_moving; ++i) {
    const std::uint64_t now = layout.slots[0].report.sequence();
    still_moving = now % 2 == 0 && now != before;
    if (!still_moving) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  for (pid_t pid : {trial.world, trial.haptic, trial.device}) kill(pid, SIGINT);
  CHECK(test::wait_for(trial.haptic, 10) == 0);
  CHECK(test::wait_for(trial.world, 10) == 0);
  CHECK(test::wait_for(trial.device, 10) == 0);
  CHECK(still_moving);
  const auto haptic_summary = nlohmann::json::parse(test::read_text(dir / "haptic.json"));
  const auto world_summary = nlohmann::json::parse(test::read_text(dir / "world.json"));
  INFO(haptic_summary.dump());
  CHECK(haptic_summary["haptic"]["channel_repairs"].get<int>() >= 1);
  CHECK(world_summary["world"]["channel_repairs"].get<int>() >= 1);
}

}  // namespace impetus
