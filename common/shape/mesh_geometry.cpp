// SPDX-License-Identifier: Apache-2.0
#include "common/shape/mesh_geometry.h"

#include <array>
#include <atomic>
#include <mutex>
#include <stdexcept>

namespace impetus {
namespace {

struct Entry {
  std::uint64_t hash = 0;
  const MeshGeometry* geometry = nullptr;
};

// Slots filled in order and never emptied: a reader scans up to the count it sees, and every slot below it was
// published (release) before the count was raised.
std::array<Entry, kMaxMeshGeometries> g_entries{};
std::atomic<std::size_t> g_count{0};
std::mutex g_register;

}  // namespace

void register_mesh_geometry(std::uint64_t hash, const MeshGeometry* geometry) {
  const std::lock_guard<std::mutex> lock(g_register);
  if (find_mesh_geometry(hash) != nullptr) return;
  const std::size_t count = g_count.load(std::memory_order_relaxed);
  if (count >= kMaxMeshGeometries) {
    throw std::length_error("more than " + std::to_string(kMaxMeshGeometries) + " distinct meshes in one process");
  }
  g_entries[count] = Entry{hash, geometry};
  g_count.store(count + 1, std::memory_order_release);
}

const MeshGeometry* find_mesh_geometry(std::uint64_t hash) {
  const std::size_t count = g_count.load(std::memory_order_acquire);
  for (std::size_t k = 0; k < count; ++k) {
    if (g_entries[k].hash == hash) return g_entries[k].geometry;
  }
  return nullptr;
}

}  // namespace impetus
