// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/segment.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

namespace impetus {
namespace {

struct SmallLayout {
  static constexpr SegmentKind kKind = SegmentKind::device_port;
  SegmentHeader header;
  std::atomic<std::uint64_t> value{0};
};

struct OtherKindLayout {
  static constexpr SegmentKind kKind = SegmentKind::world_link;
  SegmentHeader header;
  std::atomic<std::uint64_t> value{0};
};

}  // namespace

TEST_CASE("a segment is created with permissions 0600 and its header names its creator") {
  const std::string name = test::unique_segment_name("perm");
  auto segment = Segment<SmallLayout>::create(name);
  struct stat info {};
  REQUIRE(stat(("/dev/shm/" + name).c_str(), &info) == 0);
  CHECK((info.st_mode & 0777) == 0600);
  CHECK(segment->header.creator_pid == getpid());
  CHECK(segment->header.layout_version == kLayoutVersion);
  CHECK(segment.creator_alive());
}

TEST_CASE("opening a segment of another layout version fails naming both versions") {
  const std::string name = test::unique_segment_name("version");
  auto segment = Segment<SmallLayout>::create(name);
  segment->header.layout_version = kLayoutVersion + 41;
  try {
    Segment<SmallLayout>::open(name);
    FAIL("open accepted a segment of another layout version");
  } catch (const SegmentError& error) {
    const std::string message = error.what();
    CHECK_THAT(message, Catch::Contains("version " + std::to_string(kLayoutVersion + 41)));
    CHECK_THAT(message, Catch::Contains("version " + std::to_string(kLayoutVersion)));
    CHECK_THAT(message, Catch::Contains(name));
  }
}

TEST_CASE("opening a segment of another kind or a missing one fails with the reason") {
  const std::string name = test::unique_segment_name("kind");
  auto segment = Segment<SmallLayout>::create(name);
  CHECK_THROWS_WITH(Segment<OtherKindLayout>::open(name), Catch::Contains("not a world link"));
  CHECK_THROWS_WITH(Segment<SmallLayout>::open(name + "_missing"), Catch::Contains("is its creator running"));
}

TEST_CASE("a segment whose creator is alive is not taken over") {
  const std::string name = test::unique_segment_name("live");
  auto segment = Segment<SmallLayout>::create(name);
  CHECK_THROWS_WITH(Segment<SmallLayout>::create(name), Catch::Contains("a running process holds it"));
  // The failed attempt must not have removed the live segment.
  segment->value = 42;
  auto reader = Segment<SmallLayout>::open(name);
  CHECK(reader->value == 42);
}

TEST_CASE("a segment whose creator died is taken over") {
  const std::string name = test::unique_segment_name("stale");
  const pid_t creator = test::fork_child([&] {
    auto segment = Segment<SmallLayout>::create(name);
    segment->value = 1234;
    _exit(0);  // dies without removing the name, like a crash
    return 0;
  });
  REQUIRE(test::wait_child(creator) == 0);
  {
    auto stale = Segment<SmallLayout>::open(name);
    CHECK(stale->value == 1234);
    CHECK_FALSE(stale.creator_alive());
  }
  auto segment = Segment<SmallLayout>::create(name);
  CHECK(segment->value == 0);
  CHECK(segment->header.creator_pid == getpid());
}

TEST_CASE("the owner removes the segment name when it goes away") {
  const std::string name = test::unique_segment_name("remove");
  { auto segment = Segment<SmallLayout>::create(name); }
  struct stat info {};
  CHECK(stat(("/dev/shm/" + name).c_str(), &info) != 0);
}

namespace {

std::string shm_path(const std::string& name) { return "/dev/shm/" + name; }

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A file at the segment's name with `text` and `mode`, as another program or user might leave it.
void plant(const std::string& name, const std::string& text, mode_t mode) {
  std::ofstream(shm_path(name)) << text;
  REQUIRE(chmod(shm_path(name).c_str(), mode) == 0);
}

}  // namespace

TEST_CASE("another program's file at the name is refused, named and left as it was") {
  const std::string name = test::unique_segment_name("foreign");
  plant(name, "another program's data\n", 0600);
  CHECK_THROWS_WITH(Segment<SmallLayout>::create(name),
                    Catch::Contains(shm_path(name)) && Catch::Contains("not an Impetus segment"));
  CHECK_THROWS(Segment<SmallLayout>::open(name));
  CHECK(read_file(shm_path(name)) == "another program's data\n");
  std::filesystem::remove(shm_path(name));
}

TEST_CASE("a symbolic link at the name is refused and neither it nor its target is touched") {
  const std::string name = test::unique_segment_name("symlink");
  const std::string target =
      (std::filesystem::temp_directory_path() / ("impetus_victim_" + std::to_string(getpid()))).string();
  std::ofstream(target) << "precious";
  std::filesystem::remove(shm_path(name));
  std::filesystem::create_symlink(target, shm_path(name));
  CHECK_THROWS_WITH(Segment<SmallLayout>::create(name), Catch::Contains("symbolic link"));
  CHECK_THROWS_WITH(Segment<SmallLayout>::open(name), Catch::Contains("symbolic link"));
  CHECK(std::filesystem::is_symlink(shm_path(name)));
  CHECK(read_file(target) == "precious");
  std::filesystem::remove(shm_path(name));
  std::filesystem::remove(target);
}

TEST_CASE("a segment other users can open is refused by creator and opener, saying why") {
  // A valid segment of ours made world-writable (as a planted one would be): its header would pass every other check.
  const std::string name = test::unique_segment_name("mode");
  auto segment = Segment<SmallLayout>::create(name);
  REQUIRE(chmod(shm_path(name).c_str(), 0666) == 0);
  CHECK_THROWS_WITH(Segment<SmallLayout>::open(name), Catch::Contains("mode is 0666"));
  const pid_t creator = test::fork_child([&] {
    try {
      Segment<SmallLayout>::create(name);
    } catch (const SegmentError& error) {
      return std::string(error.what()).find("mode is 0666") != std::string::npos ? 0 : 2;
    }
    return 1;
  });
  CHECK(test::wait_child(creator) == 0);
}

TEST_CASE("a segment owned by another user is refused, naming the owner (as root: the planted-segment attack)") {
  if (geteuid() != 0) {
    WARN("not root: cannot give a file to another user; this check runs only as root (CI runs as root)");
    return;
  }
  // An unprivileged user's segment with a valid header: made by us, then given to `nobody`.
  const std::string name = test::unique_segment_name("owner");
  const pid_t creator = test::fork_child([&] {
    auto segment = Segment<SmallLayout>::create(name);
    _exit(0);  // leaves the name, with a valid header and a dead creator
    return 0;
  });
  REQUIRE(test::wait_child(creator) == 0);
  constexpr uid_t kNobody = 65534;
  REQUIRE(chown(shm_path(name).c_str(), kNobody, kNobody) == 0);
  CHECK_THROWS_WITH(Segment<SmallLayout>::open(name), Catch::Contains("belongs to user 65534"));
  CHECK_THROWS_WITH(Segment<SmallLayout>::create(name), Catch::Contains("belongs to user 65534"));
  CHECK(std::filesystem::exists(shm_path(name)));  // not taken over: it is not ours
  std::filesystem::remove(shm_path(name));
}

TEST_CASE("creators racing for one name: exactly one wins, every time") {
  for (int round = 0; round < 50; ++round) {
    const std::string name = test::unique_segment_name("race");
    std::atomic<int> ready{0};
    std::atomic<int> winners{0};
    std::atomic<int> other_errors{0};  // counted here: Catch2's assertions are not thread-safe
    std::vector<std::thread> creators;
    std::vector<std::unique_ptr<Segment<SmallLayout>>> segments(4);
    for (int c = 0; c < 4; ++c) {
      creators.emplace_back([&, c] {
        ready.fetch_add(1);
        while (ready.load() < 4) {
        }
        try {
          segments[c] = std::make_unique<Segment<SmallLayout>>(Segment<SmallLayout>::create(name));
          winners.fetch_add(1);
        } catch (const SegmentError& error) {
          if (error.problem() != SegmentProblem::in_use) other_errors.fetch_add(1);
        }
      });
    }
    for (auto& thread : creators) thread.join();
    INFO("round " << round);
    REQUIRE(winners.load() == 1);
    REQUIRE(other_errors.load() == 0);
  }
}

TEST_CASE("a segment file shorter than its header says is reported with the file's own size") {
  const std::string name = test::unique_segment_name("short");
  auto segment = Segment<SmallLayout>::create(name);
  REQUIRE(truncate(shm_path(name).c_str(), sizeof(SegmentHeader)) == 0);
  CHECK_THROWS_WITH(Segment<SmallLayout>::open(name),
                    Catch::Contains("the file is " + std::to_string(sizeof(SegmentHeader)) + " bytes") &&
                        Catch::Contains("shorter than the " + std::to_string(sizeof(SmallLayout))));
}

TEST_CASE("a segment's name never names a file its creator has not locked yet") {
  // The window two creators once both won through: a name that exists before its creator holds the lock lets a second
  // creator lock the file, call it stale and take the name. A watcher that keeps opening the name and trying the lock
  // while a creator creates and destroys the segment must never get the lock on a file that still has the name.
  const std::string name = test::unique_segment_name("window");
  const std::string path = shm_path(name);
  constexpr int kRounds = 2000;
  std::atomic<bool> done{false};
  std::atomic<int> unlocked_while_named{0};
  std::atomic<int> looks{0};
  std::thread watcher([&] {
    while (!done.load()) {
      const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd < 0) continue;
      looks.fetch_add(1);
      if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
        struct stat opened {};
        struct stat named {};
        if (fstat(fd, &opened) == 0 && stat(path.c_str(), &named) == 0 && opened.st_ino == named.st_ino) {
          unlocked_while_named.fetch_add(1);
        }
      }
      ::close(fd);  // releases the lock if it was taken
    }
  });
  int created = 0;
  int refused = 0;  // only possible when the watcher held the lock at the wrong moment
  for (int round = 0; round < kRounds; ++round) {
    try {
      auto segment = Segment<SmallLayout>::create(name);
      ++created;
    } catch (const SegmentError&) {
      ++refused;
    }
  }
  done.store(true);
  watcher.join();
  INFO(created << " created, " << refused << " refused, the watcher looked " << looks.load() << " times");
  CHECK(looks.load() > 0);
  CHECK(unlocked_while_named.load() == 0);
  CHECK(refused == 0);
  CHECK(created == kRounds);
}

TEST_CASE("an owner never removes a name that no longer names its own segment") {
  const std::string name = test::unique_segment_name("replaced");
  {
    auto segment = Segment<SmallLayout>::create(name);
    std::filesystem::remove(shm_path(name));  // a user removes it by hand and something else takes the name
    plant(name, "someone else's", 0600);
  }
  CHECK(read_file(shm_path(name)) == "someone else's");
  std::filesystem::remove(shm_path(name));
}

}  // namespace impetus

namespace impetus {

TEST_CASE("a read-only segment reads what the creator writes and is mapped without write permission") {
  const std::string name = test::unique_segment_name("readonly");
  auto segment = Segment<SmallLayout>::create(name);
  segment->value.store(42);
  const auto reader = ReadOnlySegment<SmallLayout>::open(name);
  CHECK(reader->value.load() == 42);
  segment->value.store(43);
  CHECK(reader->value.load() == 43);
  CHECK(reader.creator_alive());
  // The kernel's view of the mapping: /proc/self/maps lists it "r--s" (read, shared, no write).
  std::ifstream maps("/proc/self/maps");
  std::string line;
  int read_only_mappings = 0;
  int writable_mappings = 0;
  while (std::getline(maps, line)) {
    if (line.find("/dev/shm/" + name) == std::string::npos) continue;
    const std::string permissions = line.substr(line.find(' ') + 1, 4);
    if (permissions == "r--s") ++read_only_mappings;
    if (permissions == "rw-s") ++writable_mappings;
  }
  CHECK(read_only_mappings == 1);
  CHECK(writable_mappings == 1);  // the creator's own
}

TEST_CASE("a read-only open refuses what a read-write open refuses: a missing segment, another kind") {
  const std::string name = test::unique_segment_name("readonly_bad");
  try {
    ReadOnlySegment<SmallLayout>::open(name);
    FAIL("opened a missing segment");
  } catch (const SegmentError& error) {
    CHECK(error.problem() == SegmentProblem::missing);
  }
  auto segment = Segment<SmallLayout>::create(name);
  try {
    ReadOnlySegment<OtherKindLayout>::open(name);
    FAIL("opened a segment of another kind");
  } catch (const SegmentError& error) {
    CHECK(error.problem() == SegmentProblem::incompatible);
  }
}

}  // namespace impetus
