// SPDX-License-Identifier: Apache-2.0
#pragma once
// Shared by the fuzz targets: an invariant check that stays on in Release builds (assert() is compiled out by NDEBUG,
// and a fuzzer that silently skips its checks finds nothing) and aborts, which libFuzzer and the regression runner
// both report as a failure with the input that caused it.

#include <cstddef>
#include <cstdio>
#include <cstdlib>

namespace impetus::fuzz {
// Longest error message a parser may produce: a file name, a field path, a reason and a quote of at most a few
// hundred characters, whatever the size of the input.
inline constexpr std::size_t kMaxMessageChars = 1024;
}  // namespace impetus::fuzz

#define FUZZ_CHECK(condition)                                                                       \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::fprintf(stderr, "%s:%d: fuzz invariant violated: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                                 \
    }                                                                                               \
  } while (false)
