// SPDX-License-Identifier: Apache-2.0
#pragma once
// A named shared-memory segment holding one fixed-layout struct (docs/architecture.md §2).
//
// We map a plain boost::interprocess::shared_memory_object instead of a managed segment: a managed segment's allocator
// keeps a mutex in shared memory that stays locked forever if a process dies holding it. Here nothing in the segment is
// ever locked; channels are seqlocks and the only blocking primitives are the lockstep turns (futex words), which
// every waiter waits on with a timeout and a liveness check of its peer.
//
// Ownership: exactly one process creates a segment (the world manager the world link, the haptic controller the device
// port) and removes its name when it exits. Other processes open it. The creator holds an exclusive flock on the file
// for its whole life (the kernel drops it when the process dies, however it dies). It makes the file without a name,
// locks and sizes it, and only then links it to the name, which fails if the name exists: so a name always names a
// locked file while its creator lives, of several creators started at once exactly one wins, and a segment whose lock
// is free is stale: the next creator takes it over.
//
// Nothing that is not ours is used or removed: every open checks, on the descriptor, that the file is a regular file
// owned by this user with no access for others (0600); a symbolic link at the name is never followed; a file without
// an Impetus header (another program's) is refused with its path and left alone; a creator removes a name only while
// holding its lock and only if the name still refers to its own file. A segment with another layout version is
// refused with both versions in the message.

#include <atomic>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace impetus {

inline constexpr std::uint64_t kSegmentMagic = 0x31535554'45504D49ull;  // "IMPETUS1" in little-endian bytes
inline constexpr std::uint32_t kLayoutVersion = 26;  // bump on any change to wire_frames.h or a *Layout struct

enum class SegmentKind : std::uint32_t { world_link = 1, device_port = 2, world_view = 3, touch_port = 4 };
const char* to_string(SegmentKind kind);

struct SegmentHeader {
  // Written last (release) when the creator has finished constructing the layout; 0 while under construction.
  std::atomic<std::uint64_t> magic;
  std::uint32_t layout_version;
  SegmentKind kind;
  std::uint64_t layout_size_bytes;
  std::int32_t creator_pid;
  std::uint32_t reserved;
  std::uint64_t creator_start_ticks;  // /proc/PID/stat start time: tells a live creator from a reused pid
  std::int64_t created_unix_ns;       // CLOCK_REALTIME at creation, for humans and logs
};
static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

// Why a segment could not be created or opened. Callers decide on the reason, never on the message text.
enum class SegmentProblem {
  missing,             // no segment of that name (its creator has not started yet, or has exited)
  under_construction,  // its creator is still constructing it
  incompatible,        // another layout version, kind or size, or not an Impetus segment
  in_use,              // create: a live process owns a segment of that name
  system,              // the operating system refused (permissions, memory)
};

class SegmentError : public std::runtime_error {
 public:
  SegmentError(SegmentProblem problem, const std::string& message) : std::runtime_error(message), problem_(problem) {}
  SegmentProblem problem() const { return problem_; }
  // Worth retrying: the segment may appear or finish construction.
  bool transient() const {
    return problem_ == SegmentProblem::missing || problem_ == SegmentProblem::under_construction;
  }

 private:
  SegmentProblem problem_;
};

// Whether the process that created a segment still runs (the pid exists and has the recorded start time).
bool creator_alive(const SegmentHeader& header);

// Process start time of `pid` in clock ticks since boot, or 0 if the process does not exist.
std::uint64_t process_start_ticks(int pid);

// How a process maps a segment: its creator, a peer that writes its own channels, or a reader that cannot write a byte
// of it (a viewer: the kernel refuses its stores, so nothing it does can disturb the link).
enum class SegmentAccess { create, read_write, read_only };

// Untyped mapping; Segment<Layout> and ReadOnlySegment<Layout> below are what code uses.
class SegmentMapping {
 public:
  SegmentMapping(const std::string& name, SegmentKind kind, std::size_t size_bytes, SegmentAccess access);
  ~SegmentMapping();
  SegmentMapping(const SegmentMapping&) = delete;
  SegmentMapping& operator=(const SegmentMapping&) = delete;

  void* address() const;
  const std::string& name() const { return name_; }
  bool owner() const { return owner_; }
  // Stamps the header and publishes the magic; the creator calls it after constructing the layout.
  void publish_header(SegmentKind kind, std::size_t size_bytes);

  struct Impl;  // public so the implementation's helpers can take it; its definition stays in segment.cpp

 private:
  std::unique_ptr<Impl> impl_;
  std::string name_;
  bool owner_ = false;
};

// Layout must start with `SegmentHeader header;` and be default-constructible; it is constructed in place by the
// creator (after the memory is zeroed) and never destroyed (other processes may still have it mapped).
template <class Layout>
class Segment {
  static_assert(std::is_standard_layout_v<Layout>, "a segment layout must be standard-layout");

 public:
  // Creates the segment (mode 0600), taking over a stale one whose creator is dead. Throws SegmentError if a live
  // process owns it. `configure(Layout&)` runs after construction and before the header is published, so openers
  // never see a half-configured layout.
  template <class Configure>
  static Segment create(const std::string& name, Configure&& configure) {
    Segment segment(name, true);
    configure(*segment.layout_);
    segment.mapping_->publish_header(Layout::kKind, sizeof(Layout));
    return segment;
  }
  static Segment create(const std::string& name) {
    return create(name, [](Layout&) {});
  }
  // Opens an existing segment. Throws SegmentError if it is missing, still under construction, of another kind, size
  // or layout version.
  static Segment open(const std::string& name) { return Segment(name, false); }

  Layout& operator*() const { return *layout_; }
  Layout* operator->() const { return layout_; }
  const std::string& name() const { return mapping_->name(); }
  // False once the creator has died or removed the name: a reader should re-open to re-attach.
  bool creator_alive() const { return impetus::creator_alive(layout_->header); }

 private:
  Segment(const std::string& name, bool create)
      : mapping_(std::make_unique<SegmentMapping>(name, Layout::kKind, sizeof(Layout),
                                                  create ? SegmentAccess::create : SegmentAccess::read_write)),
        layout_(static_cast<Layout*>(mapping_->address())) {
    if (create) new (layout_) Layout();
  }

  std::unique_ptr<SegmentMapping> mapping_;
  Layout* layout_;
};

// A segment mapped read-only (PROT_READ): its channels can be read (seqlock reads only load), nothing can be written.
template <class Layout>
class ReadOnlySegment {
  static_assert(std::is_standard_layout_v<Layout>, "a segment layout must be standard-layout");

 public:
  // Throws SegmentError as Segment<Layout>::open does.
  static ReadOnlySegment open(const std::string& name) { return ReadOnlySegment(name); }

  const Layout& operator*() const { return *layout_; }
  const Layout* operator->() const { return layout_; }
  const std::string& name() const { return mapping_->name(); }
  bool creator_alive() const { return impetus::creator_alive(layout_->header); }

 private:
  explicit ReadOnlySegment(const std::string& name)
      : mapping_(std::make_unique<SegmentMapping>(name, Layout::kKind, sizeof(Layout), SegmentAccess::read_only)),
        layout_(static_cast<const Layout*>(mapping_->address())) {}

  std::unique_ptr<SegmentMapping> mapping_;
  const Layout* layout_;
};

}  // namespace impetus
