#include "common/link/shm/segment.h"
#include "test_support.h"

#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <atomic>

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
  CHECK_THROWS_WITH(Segment<SmallLayout>::create(name), Catch::Contains("in use by running process"));
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

}  // namespace impetus
