// SPDX-License-Identifier: Apache-2.0
#pragma once
// An allocator for large read-mostly arrays walked at random by the servo (a mesh's tree): memory of 2 MB or more is
// aligned to 2 MB and marked for the kernel's transparent huge pages (madvise MADV_HUGEPAGE) before it is touched,
// so a 70 MB tree takes 35 page-table entries instead of 17 500. A walk that reaches a part of the tree not visited
// for a while then misses the cache on the node, not also on the translation of its address (docs/meshes.md).
// Smaller requests, and systems without the advice, get ordinary memory; the contents are the same either way.

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace impetus {

inline constexpr std::size_t kHugePage_bytes = std::size_t{2} << 20;

template <typename T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() noexcept = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}  // NOLINT: rebinding, as the standard asks

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePage_bytes) {
      return static_cast<T*>(::operator new(bytes, std::align_val_t{alignof(T) > 64 ? alignof(T) : 64}));
    }
    const std::size_t rounded = (bytes + kHugePage_bytes - 1) / kHugePage_bytes * kHugePage_bytes;
    void* memory = std::aligned_alloc(kHugePage_bytes, rounded);
    if (memory == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    ::madvise(memory, rounded, MADV_HUGEPAGE);  // advice only: without it the pages are ordinary ones
#endif
    return static_cast<T*>(memory);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePage_bytes) {
      ::operator delete(p, std::align_val_t{alignof(T) > 64 ? alignof(T) : 64});
      return;
    }
    std::free(p);
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

template <typename T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace impetus
