// SPDX-License-Identifier: Apache-2.0
#include "common/link/dds/dds_codec.h"

#include "common/link/frame_fields.h"

#include <dds/dds.h>

#include <algorithm>
#include <cstddef>

namespace impetus {
namespace {

// Field conversions between the wire frames and the IDL types: Vec3 is std::array<double, 3> on one side and
// struct {x, y, z} on the other; the coupling an enum and an unsigned; the rest the same type.
struct ToDds {
  void operator()(const Vec3& from, impetus_dds_Vec3& to) const { to = {from[0], from[1], from[2]}; }
  template <std::size_t N>
  void operator()(const std::array<double, N>& from, double (&to)[N]) const {
    std::copy(from.begin(), from.end(), to);
  }
  // A bounded sequence (allocated to N): all of it; the caller shortens what it need not send.
  template <std::size_t N>
  void operator()(const std::array<double, N>& from, dds_sequence_double& to) const {
    std::copy(from.begin(), from.end(), to._buffer);
    to._length = static_cast<std::uint32_t>(N);
  }
  void operator()(const Coupling& from, std::uint32_t& to) const { to = static_cast<std::uint32_t>(from); }
  void operator()(const ShapeKind& from, std::uint32_t& to) const { to = static_cast<std::uint32_t>(from); }
  template <class T>
  void operator()(const T& from, T& to) const {
    to = from;
  }
};

struct FromDds {
  void operator()(Vec3& to, const impetus_dds_Vec3& from) const { to = {from.x, from.y, from.z}; }
  template <std::size_t N>
  void operator()(std::array<double, N>& to, const double (&from)[N]) const {
    std::copy(from, from + N, to.begin());
  }
  // What was sent (its length checked by the caller), zeros after.
  template <std::size_t N>
  void operator()(std::array<double, N>& to, const dds_sequence_double& from) const {
    const std::size_t sent = std::min<std::size_t>(from._length, N);
    std::copy(from._buffer, from._buffer + sent, to.begin());
    std::fill(to.begin() + static_cast<std::ptrdiff_t>(sent), to.end(), 0.0);
  }
  void operator()(Coupling& to, const std::uint32_t& from) const { to = static_cast<Coupling>(from); }
  void operator()(ShapeKind& to, const std::uint32_t& from) const { to = static_cast<ShapeKind>(from); }
  template <class T>
  void operator()(T& to, const T& from) const {
    to = from;
  }
};

// The visitors call f(a.x, b.x); these adapt them to (wire, dds) argument order in both directions.
struct WireToDds {
  template <class W, class D>
  void operator()(const W& wire_field, D& dds_field) const {
    ToDds{}(wire_field, dds_field);
  }
};
struct DdsToWire {
  template <class W, class D>
  void operator()(W& wire_field, const D& dds_field) const {
    FromDds{}(wire_field, dds_field);
  }
};

}  // namespace

DdsFrameSample::DdsFrameSample() {
  allocate_sequence(sample_.planes, kMaxPlanes);
  allocate_sequence(sample_.dent_patch.height_m, kDentPatchSide * kDentPatchSide);
}
DdsFrameSample::~DdsFrameSample() { dds_sample_free(&sample_, &impetus_dds_PlaneFrame_desc, DDS_FREE_CONTENTS); }

DdsReportSample::DdsReportSample() {
  allocate_sequence(sample_.entries, kMaxImpulseEntries);
}
DdsReportSample::~DdsReportSample() {
  dds_sample_free(&sample_, &impetus_dds_HapticReport_desc, DDS_FREE_CONTENTS);
}

void to_dds(const wire::PlaneFrame& frame, std::uint64_t client_id, std::uint32_t client_endpoint,
            std::uint64_t world_id, impetus_dds_PlaneFrame& out) {
  out.client_id = client_id;
  out.client_endpoint = client_endpoint;
  out.world_id = world_id;
  out.checksum = frame.checksum;
  fields::visit_frame_header(frame, out, WireToDds{});
  // The heights only with a patch: a frame without one (every scene without clay) sends 8 KB less.
  if (frame.dent_patch.object_id < 0) out.dent_patch.height_m._length = 0;
  const std::uint32_t count = std::min(frame.plane_count, kMaxPlanes);
  for (std::uint32_t k = 0; k < count; ++k) fields::visit_plane(frame.planes[k], out.planes._buffer[k], WireToDds{});
  out.planes._length = count;
}

void to_dds(const wire::HapticReport& report, std::uint64_t client_id, std::uint32_t client_endpoint,
            std::uint64_t world_id, impetus_dds_HapticReport& out) {
  out.client_id = client_id;
  out.client_endpoint = client_endpoint;
  out.world_id = world_id;
  out.checksum = report.checksum;
  fields::visit_report_header(report, out, WireToDds{});
  const std::uint32_t count = std::min(report.entry_count, kMaxImpulseEntries);
  for (std::uint32_t k = 0; k < count; ++k) fields::visit_entry(report.entries[k], out.entries._buffer[k], WireToDds{});
  out.entries._length = count;
}

bool from_dds(const impetus_dds_PlaneFrame& in, wire::PlaneFrame& out) {
  if (in.plane_count != in.planes._length || in.plane_count > kMaxPlanes) return false;
  if (in.dent_patch.height_m._length != (in.dent_patch.object_id >= 0 ? kDentPatchSide * kDentPatchSide : 0u)) {
    return false;
  }
  out.checksum = in.checksum;
  fields::visit_frame_header(out, in, DdsToWire{});
  for (std::uint32_t k = 0; k < in.plane_count; ++k) fields::visit_plane(out.planes[k], in.planes._buffer[k], DdsToWire{});
  return true;
}

bool from_dds(const impetus_dds_HapticReport& in, wire::HapticReport& out) {
  if (in.entry_count != in.entries._length || in.entry_count > kMaxImpulseEntries) return false;
  out.checksum = in.checksum;
  fields::visit_report_header(out, in, DdsToWire{});
  for (std::uint32_t k = 0; k < in.entry_count; ++k) {
    fields::visit_entry(out.entries[k], in.entries._buffer[k], DdsToWire{});
  }
  return true;
}

void to_dds(const LoopStats& in, impetus_dds_LoopStats& out) { fields::visit_loop_stats(in, out, WireToDds{}); }

void from_dds(const impetus_dds_LoopStats& in, LoopStats& out) {
  out = LoopStats{};
  fields::visit_loop_stats(out, in, DdsToWire{});
}

}  // namespace impetus
