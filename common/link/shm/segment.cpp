#include "common/link/shm/segment.h"

#include <boost/interprocess/exceptions.hpp>
#include <boost/interprocess/mapped_region.hpp>
#include <boost/interprocess/shared_memory_object.hpp>

#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace impetus {
namespace bip = boost::interprocess;

namespace {

constexpr unsigned kSegmentPermissions = 0600;  // owner only: the link carries control data for a force device

std::int64_t unix_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

}  // namespace

const char* to_string(SegmentKind kind) {
  switch (kind) {
    case SegmentKind::world_link: return "world link";
    case SegmentKind::device_port: return "device port";
  }
  return "unknown segment kind";
}

std::uint64_t process_start_ticks(int pid) {
  if (pid <= 0) return 0;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return 0;
  // Field 2 (comm) is parenthesised and may contain spaces; fields after the last ')' are space-separated, and the
  // start time is field 22, i.e. the 20th after the ')'.
  const auto close = line.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(line.substr(close + 1));
  std::string field;
  for (int index = 3; index <= 22 && (rest >> field); ++index) {
    if (index == 22) return std::stoull(field);
  }
  return 0;
}

bool creator_alive(const SegmentHeader& header) {
  const int pid = header.creator_pid;
  if (pid <= 0) return false;
  if (kill(pid, 0) != 0 && errno == ESRCH) return false;
  const std::uint64_t start = process_start_ticks(pid);
  // A different start time means the pid was reused by an unrelated process after the creator died.
  return start != 0 && start == header.creator_start_ticks;
}

struct SegmentMapping::Impl {
  bip::shared_memory_object object;
  bip::mapped_region region;
};

namespace {

struct OpenProblem {
  SegmentProblem problem = SegmentProblem::system;
  std::string reason;  // empty: the segment can be used
};

// Opens `name` read-write and checks its header.
OpenProblem check_existing(SegmentMapping::Impl& impl, const std::string& name, SegmentKind kind,
                           std::size_t size_bytes) {
  try {
    impl.object = bip::shared_memory_object(bip::open_only, name.c_str(), bip::read_write);
  } catch (const bip::interprocess_exception& error) {
    if (error.get_error_code() == bip::not_found_error) {
      return {SegmentProblem::missing, "it does not exist (is its creator running?)"};
    }
    throw;
  }
  bip::offset_t actual_size = 0;
  impl.object.get_size(actual_size);
  if (static_cast<std::size_t>(actual_size) < sizeof(SegmentHeader)) {
    // The creator sizes the segment right after creating it: a short one is a creation under way.
    return {SegmentProblem::under_construction,
            "it is " + std::to_string(actual_size) + " bytes, too small for a header (still being created?)"};
  }
  impl.region = bip::mapped_region(impl.object, bip::read_write);
  const auto& header = *static_cast<const SegmentHeader*>(impl.region.get_address());
  const std::uint64_t magic = header.magic.load(std::memory_order_acquire);
  if (magic == 0) return {SegmentProblem::under_construction, "it is still being created"};
  if (magic != kSegmentMagic) return {SegmentProblem::incompatible, "it is not an Impetus segment (bad magic)"};
  if (header.layout_version != kLayoutVersion) {
    return {SegmentProblem::incompatible, "it has layout version " + std::to_string(header.layout_version) +
                                              " but this program uses version " + std::to_string(kLayoutVersion) +
                                              " (rebuild both sides from the same source)"};
  }
  if (header.kind != kind) {
    return {SegmentProblem::incompatible, std::string("it is a ") + to_string(header.kind) + ", not a " +
                                              to_string(kind)};
  }
  if (header.layout_size_bytes != size_bytes || static_cast<std::size_t>(actual_size) < size_bytes) {
    return {SegmentProblem::incompatible, "its layout is " + std::to_string(header.layout_size_bytes) +
                                              " bytes but this program expects " + std::to_string(size_bytes)};
  }
  return {};
}

}  // namespace

SegmentMapping::SegmentMapping(const std::string& name, SegmentKind kind, std::size_t size_bytes, bool create)
    : impl_(std::make_unique<Impl>()), name_(name), owner_(create) {
  const std::string what = std::string(to_string(kind)) + " segment '" + name + "'";
  try {
    if (!create) {
      const OpenProblem problem = check_existing(*impl_, name, kind, size_bytes);
      if (!problem.reason.empty()) throw SegmentError(problem.problem, "cannot open " + what + ": " + problem.reason);
      return;
    }
    bip::permissions permissions;
    permissions.set_permissions(kSegmentPermissions);
    try {
      impl_->object = bip::shared_memory_object(bip::create_only, name.c_str(), bip::read_write, permissions);
    } catch (const bip::interprocess_exception& error) {
      if (error.get_error_code() != bip::already_exists_error) throw;
      // A segment of that name exists: refuse if its creator lives, otherwise take it over.
      Impl existing;
      existing.object = bip::shared_memory_object(bip::open_only, name.c_str(), bip::read_write);
      bip::offset_t existing_size = 0;
      existing.object.get_size(existing_size);
      if (static_cast<std::size_t>(existing_size) >= sizeof(SegmentHeader)) {
        existing.region = bip::mapped_region(existing.object, bip::read_only);
        const auto& header = *static_cast<const SegmentHeader*>(existing.region.get_address());
        if (header.magic.load(std::memory_order_acquire) == kSegmentMagic && impetus::creator_alive(header)) {
          throw SegmentError(SegmentProblem::in_use, "cannot create " + what + ": it is in use by running process " +
                             std::to_string(header.creator_pid) + " (stop it, or choose another --shm name)");
        }
      }
      bip::shared_memory_object::remove(name.c_str());
      impl_->object = bip::shared_memory_object(bip::create_only, name.c_str(), bip::read_write, permissions);
    }
    impl_->object.truncate(static_cast<bip::offset_t>(size_bytes));
    impl_->region = bip::mapped_region(impl_->object, bip::read_write);
    std::memset(impl_->region.get_address(), 0, size_bytes);
  } catch (const bip::interprocess_exception& error) {
    if (create) bip::shared_memory_object::remove(name.c_str());
    throw SegmentError(SegmentProblem::system,
                       "cannot " + std::string(create ? "create " : "open ") + what + ": " + error.what());
  }
}

void SegmentMapping::publish_header(SegmentKind kind, std::size_t size_bytes) {
  auto& header = *static_cast<SegmentHeader*>(impl_->region.get_address());
  header.layout_version = kLayoutVersion;
  header.kind = kind;
  header.layout_size_bytes = size_bytes;
  header.creator_pid = static_cast<std::int32_t>(getpid());
  header.creator_start_ticks = process_start_ticks(getpid());
  header.created_unix_ns = unix_now_ns();
  header.magic.store(kSegmentMagic, std::memory_order_release);
}

SegmentMapping::~SegmentMapping() {
  if (owner_) bip::shared_memory_object::remove(name_.c_str());
}

void* SegmentMapping::address() const { return impl_->region.get_address(); }

}  // namespace impetus
