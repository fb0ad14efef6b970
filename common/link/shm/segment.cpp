// SPDX-License-Identifier: Apache-2.0
#include "common/link/shm/segment.h"

#include <boost/interprocess/exceptions.hpp>
#include <boost/interprocess/mapped_region.hpp>
#include <boost/interprocess/shared_memory_object.hpp>

#include <signal.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
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

struct OpenProblem {
  SegmentProblem problem = SegmentProblem::system;
  std::string reason;  // empty: the segment can be used
};

}  // namespace

const char* to_string(SegmentKind kind) {
  switch (kind) {
    case SegmentKind::world_link: return "world link";
    case SegmentKind::device_port: return "device port";
    case SegmentKind::world_view: return "world view";
    case SegmentKind::touch_port: return "touch port";
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
  bool locked = false;  // this process holds the creator's lock on `object`
  int lock_fd = -1;     // a creator: the descriptor it made the file with, which holds the lock for its life
  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (lock_fd >= 0) close(lock_fd);
  }
};

namespace {

// Where the system keeps a segment's file (Linux: POSIX shared memory lives in /dev/shm), for messages and checks.
std::string segment_path(const std::string& name) { return "/dev/shm/" + name; }

int descriptor(const SegmentMapping::Impl& impl) { return impl.object.get_mapping_handle().handle; }

// Why the file behind an open segment is not one this process may use, or "" if it is: it must be a regular file
// owned by this user that nobody else can read or write. Checked on the descriptor, so a rename between the open and
// the check changes nothing. A symbolic link never gets this far: shm_open opens with O_NOFOLLOW.
std::string foreign_reason(int fd) {
  struct stat status {};
  if (fstat(fd, &status) != 0) return std::string("cannot inspect it: ") + std::strerror(errno);
  if (!S_ISREG(status.st_mode)) return "it is not a regular file";
  if (status.st_uid != geteuid()) {
    return "it belongs to user " + std::to_string(status.st_uid) + ", not to this process's user " +
           std::to_string(geteuid()) + " (someone else may have planted it)";
  }
  if ((status.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(status.st_mode & 07777));
    return std::string("its mode is ") + mode + ": other users can open it (Impetus segments are 0600)";
  }
  return "";
}

// Opens an existing segment file (read-write, or read-only for a reader that must not write). A name that is a symbolic link (ELOOP) or that we may not open is
// reported as incompatible; only a missing name is `missing`.
OpenProblem open_existing(SegmentMapping::Impl& impl, const std::string& name, bip::mode_t mode = bip::read_write) {
  try {
    impl.object = bip::shared_memory_object(bip::open_only, name.c_str(), mode);
  } catch (const bip::interprocess_exception& error) {
    if (error.get_error_code() == bip::not_found_error) {
      return {SegmentProblem::missing, "it does not exist (is its creator running?)"};
    }
    if (error.get_native_error() == ELOOP) {
      return {SegmentProblem::incompatible, segment_path(name) + " is a symbolic link, not an Impetus segment"};
    }
    return {SegmentProblem::incompatible, "cannot open " + segment_path(name) + ": " + error.what()};
  }
  if (std::string reason = foreign_reason(descriptor(impl)); !reason.empty()) {
    return {SegmentProblem::incompatible, segment_path(name) + ": " + reason};
  }
  return {};
}

// Why the header of an open segment does not match what this program expects, or "" if it does.
OpenProblem check_header(SegmentMapping::Impl& impl, SegmentKind kind, std::size_t size_bytes, bip::mode_t mode) {
  bip::offset_t actual_size = 0;
  impl.object.get_size(actual_size);
  if (static_cast<std::size_t>(actual_size) < sizeof(SegmentHeader)) {
    // The creator sizes the segment right after creating it: a short one is a creation under way.
    return {SegmentProblem::under_construction,
            "it is " + std::to_string(actual_size) + " bytes, too small for a header (still being created?)"};
  }
  impl.region = bip::mapped_region(impl.object, mode);
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
  if (header.layout_size_bytes != size_bytes) {
    return {SegmentProblem::incompatible, "its layout is " + std::to_string(header.layout_size_bytes) +
                                              " bytes but this program expects " + std::to_string(size_bytes)};
  }
  if (static_cast<std::size_t>(actual_size) < size_bytes) {
    return {SegmentProblem::incompatible, "the file is " + std::to_string(actual_size) + " bytes, shorter than the " +
                                              std::to_string(size_bytes) + " its header says (cut short?)"};
  }
  return {};
}

// The creator's lock: an exclusive flock on the segment's file, held for the creator's life and released by the
// kernel when it dies, however it dies. Whoever holds it owns the name; nobody else ever removes it.
bool take_creator_lock(SegmentMapping::Impl& impl) {
  while (flock(descriptor(impl), LOCK_EX | LOCK_NB) != 0) {
    if (errno != EINTR) return false;
  }
  impl.locked = true;
  return true;
}

// Whether `name` still names the file `impl` has open (a name is only ever removed by the lock holder, but a user may
// have removed it by hand and another creator made a new one).
bool names_our_file(const SegmentMapping::Impl& impl, const std::string& name) {
  struct stat ours {};
  struct stat named {};
  if (fstat(descriptor(impl), &ours) != 0 || lstat(segment_path(name).c_str(), &named) != 0) return false;
  return ours.st_dev == named.st_dev && ours.st_ino == named.st_ino;
}

// Whether a segment whose creator's lock is free may be taken over: it is an Impetus segment left by a creator that
// died, or an empty or zero-headed file left by a creation cut short. Anything else is another program's file.
OpenProblem stale_reason(SegmentMapping::Impl& impl) {
  bip::offset_t size = 0;
  impl.object.get_size(size);
  if (size == 0) return {};
  if (static_cast<std::size_t>(size) < sizeof(SegmentHeader)) {
    return {SegmentProblem::incompatible, "it is " + std::to_string(size) + " bytes and not an Impetus segment"};
  }
  impl.region = bip::mapped_region(impl.object, bip::read_only);
  const auto* bytes = static_cast<const unsigned char*>(impl.region.get_address());
  const auto& header = *reinterpret_cast<const SegmentHeader*>(bytes);
  const std::uint64_t magic = header.magic.load(std::memory_order_acquire);
  if (magic == kSegmentMagic) {
    // A creator of an older build held no lock: its liveness is still told by pid and start time.
    if (creator_alive(header)) {
      return {SegmentProblem::in_use, "it is in use by running process " + std::to_string(header.creator_pid)};
    }
    return {};
  }
  for (std::size_t i = 0; i < sizeof(SegmentHeader); ++i) {
    if (bytes[i] != 0) return {SegmentProblem::incompatible, "it is not an Impetus segment (bad magic)"};
  }
  return {};
}


// A new file for a segment of `size_bytes`, with no name yet, locked (the creator's lock) and sized: -1 with errno set
// if the system refuses. Nobody can open a file without a name, so nobody sees it before it is locked and sized.
int make_locked_file(std::size_t size_bytes) {
  const int fd = open("/dev/shm", O_TMPFILE | O_RDWR | O_CLOEXEC, kSegmentPermissions);
  if (fd < 0) return -1;
  // O_TMPFILE applies the umask; a segment is 0600 whatever the umask.
  if (fchmod(fd, kSegmentPermissions) != 0 || flock(fd, LOCK_EX | LOCK_NB) != 0 ||
      ftruncate(fd, static_cast<off_t>(size_bytes)) != 0) {
    const int error = errno;
    close(fd);
    errno = error;
    return -1;
  }
  return fd;
}

// Gives the file `fd` the segment name `name`, atomically and only if the name is free (EEXIST otherwise): a name
// therefore always names a file its creator has already locked.
bool publish_name(int fd, const std::string& name) {
  const std::string self = "/proc/self/fd/" + std::to_string(fd);
  return linkat(AT_FDCWD, self.c_str(), AT_FDCWD, segment_path(name).c_str(), AT_SYMLINK_FOLLOW) == 0;
}

// Whether the descriptors `a` and `b` are the same file.
bool same_file(int a, int b) {
  struct stat first {};
  struct stat second {};
  return fstat(a, &first) == 0 && fstat(b, &second) == 0 && first.st_dev == second.st_dev &&
         first.st_ino == second.st_ino;
}

}  // namespace

SegmentMapping::SegmentMapping(const std::string& name, SegmentKind kind, std::size_t size_bytes,
                               SegmentAccess access)
    : impl_(std::make_unique<Impl>()), name_(name), owner_(false) {
  const bool create = access == SegmentAccess::create;
  const bip::mode_t mode = access == SegmentAccess::read_only ? bip::read_only : bip::read_write;
  const std::string what = std::string(to_string(kind)) + " segment '" + name + "'";
  const auto refuse = [&](const OpenProblem& problem, const char* verb) {
    throw SegmentError(problem.problem, std::string("cannot ") + verb + " " + what + ": " + problem.reason);
  };
  try {
    if (!create) {
      if (OpenProblem problem = open_existing(*impl_, name, mode); !problem.reason.empty()) refuse(problem, "open");
      if (OpenProblem problem = check_header(*impl_, kind, size_bytes, mode); !problem.reason.empty()) {
        refuse(problem, "open");
      }
      return;
    }
    // The file is made without a name, locked and sized, and only then given the name (make_locked_file,
    // publish_name): so a segment whose lock is free is never one still being created, and of several creators
    // started at once exactly one names its file.
    const int fd = make_locked_file(size_bytes);
    if (fd < 0) {
      refuse({SegmentProblem::system, std::string("cannot make its file in /dev/shm: ") + std::strerror(errno)},
             "create");
    }
    impl_->lock_fd = fd;
    const OpenProblem racing{SegmentProblem::in_use, "another process is creating it at the same moment"};
    if (!publish_name(fd, name)) {
      if (errno != EEXIST) {
        refuse({SegmentProblem::system, "cannot name " + segment_path(name) + ": " + std::strerror(errno)}, "create");
      }
      // The name exists. Take it over only if nobody holds its creator's lock and it is ours and stale.
      Impl existing;
      if (OpenProblem problem = open_existing(existing, name); !problem.reason.empty()) {
        if (problem.problem == SegmentProblem::missing) problem = racing;  // removed by a taker since our attempt
        refuse(problem, "create");
      }
      if (!take_creator_lock(existing)) {
        refuse({SegmentProblem::in_use, "a running process holds it (stop it, or choose another --shm name)"},
               "create");
      }
      if (OpenProblem problem = stale_reason(existing); !problem.reason.empty()) {
        if (problem.problem == SegmentProblem::incompatible) {
          problem.reason = segment_path(name) + ": " + problem.reason +
                           "; it is left alone (remove it yourself if it is not needed, or choose another --shm name)";
        }
        refuse(problem, "create");
      }
      // Holding the lock, we are the only process that may remove this file's name.
      if (names_our_file(existing, name)) bip::shared_memory_object::remove(name.c_str());
      if (!publish_name(fd, name)) refuse(racing, "create");
    }
    owner_ = true;
    impl_->object = bip::shared_memory_object(bip::open_only, name.c_str(), bip::read_write);
    // Only the holder of our lock removes our name, so the name still names our file.
    if (!same_file(descriptor(*impl_), fd)) refuse(racing, "create");
    impl_->locked = true;
    impl_->region = bip::mapped_region(impl_->object, bip::read_write);
    std::memset(impl_->region.get_address(), 0, size_bytes);
  } catch (const bip::interprocess_exception& error) {
    if (owner_ && names_our_file(*impl_, name)) bip::shared_memory_object::remove(name.c_str());
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
  // Only our own file's name: never one a user or another creator has put in its place.
  if (owner_ && names_our_file(*impl_, name_)) bip::shared_memory_object::remove(name_.c_str());
}

void* SegmentMapping::address() const { return impl_->region.get_address(); }

}  // namespace impetus
