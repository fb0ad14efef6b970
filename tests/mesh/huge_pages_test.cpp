// SPDX-License-Identifier: Apache-2.0
// The allocator of a mesh's large arrays (common/mesh/huge_pages.h): where its memory starts, and that the arrays hold
// what they are given whichever memory they get.

#include "common/mesh/huge_pages.h"
#include "common/mesh/mesh_bvh.h"

#include "tests/support/mesh_shapes.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <numeric>

using namespace impetus;

TEST_CASE("huge pages: a large array starts on a 2 MB boundary, a small one on a cache line, and both keep values") {
  HugeVector<std::uint32_t> large(kHugePage_bytes / sizeof(std::uint32_t) + 7);
  std::iota(large.begin(), large.end(), 0u);
  CHECK(reinterpret_cast<std::uintptr_t>(large.data()) % kHugePage_bytes == 0);
  HugeVector<std::uint32_t> small(100);
  std::iota(small.begin(), small.end(), 0u);
  CHECK(reinterpret_cast<std::uintptr_t>(small.data()) % 64 == 0);
  // Grown across the boundary by push_back: every value moves with it.
  for (std::uint32_t k = 0; k < kHugePage_bytes / sizeof(std::uint32_t); ++k) small.push_back(100 + k);
  CHECK(reinterpret_cast<std::uintptr_t>(small.data()) % kHugePage_bytes == 0);
  bool kept = true;
  for (std::size_t k = 0; k < small.size(); ++k) kept = kept && small[k] == k;
  CHECK(kept);
  CHECK(large.back() == large.size() - 1);
}

TEST_CASE("huge pages: a tree over 80 k triangles, its arrays in huge pages, answers as brute force does") {
  const TriangleMesh mesh = impetus::test::icosphere(0.05, 6);  // 81 920 triangles: its node array is past 2 MB
  const MeshBvh tree(mesh);
  REQUIRE(tree.node_count() * sizeof(Eigen::AlignedBox3d) > kHugePage_bytes);  // each node holds a box at least
  for (const Eigen::Vector3d& query : {Eigen::Vector3d(0.01, 0.02, 0.06), Eigen::Vector3d(-0.03, 0.0, 0.02)}) {
    MeshPoint found;
    REQUIRE(tree.nearest(query, found));
    CHECK(std::abs(found.signed_distance_m) ==
          Approx(impetus::test::brute_force_distance(mesh, query)).margin(1e-15));
  }
}
