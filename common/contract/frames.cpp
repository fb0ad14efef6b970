// SPDX-License-Identifier: Apache-2.0
#include "common/contract/frames.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

namespace impetus {

const char* to_string(Coupling coupling) {
  switch (coupling) {
    case Coupling::impulse: return "impulse";
    case Coupling::position: return "position";
    case Coupling::local: return "local";
  }
  return "unknown";
}

namespace {

// The header is every member before the array (its offset, so a new header field is copied without a change here),
// then the used slots; the slots the destination used beyond the new count are reset.
template <class Frame, class Slot, std::size_t kCapacity>
void copy_used_slots(const Frame& from, Frame& to, std::array<Slot, kCapacity> Frame::*slots,
                     std::uint32_t Frame::*count, std::size_t header_bytes) noexcept {
  if (&from == &to) return;
  const std::size_t used_before = std::min<std::size_t>(to.*count, kCapacity);
  const std::size_t used = std::min<std::size_t>(from.*count, kCapacity);
  std::memcpy(static_cast<void*>(&to), &from, header_bytes);
  std::copy_n((from.*slots).begin(), used, (to.*slots).begin());
  for (std::size_t k = used; k < used_before; ++k) (to.*slots)[k] = Slot{};
}

}  // namespace

static_assert(std::is_standard_layout_v<PlaneFrame> && std::is_standard_layout_v<HapticReport>);
static_assert(offsetof(PlaneFrame, planes) + sizeof(PlaneFrame::planes) == sizeof(PlaneFrame));
static_assert(offsetof(HapticReport, entries) + sizeof(HapticReport::entries) == sizeof(HapticReport));

void copy_used(const PlaneFrame& from, PlaneFrame& to) noexcept {
  copy_used_slots(from, to, &PlaneFrame::planes, &PlaneFrame::plane_count, offsetof(PlaneFrame, planes));
}

void copy_used(const HapticReport& from, HapticReport& to) noexcept {
  copy_used_slots(from, to, &HapticReport::entries, &HapticReport::entry_count, offsetof(HapticReport, entries));
}

}  // namespace impetus
