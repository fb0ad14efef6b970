#pragma once
// Shared by the fuzz targets: an invariant check that stays on in Release builds (assert() is compiled out by NDEBUG,
// and a fuzzer that silently skips its checks finds nothing) and aborts, which libFuzzer and the regression runner
// both report as a failure with the input that caused it.

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition)                                                                       \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::fprintf(stderr, "%s:%d: fuzz invariant violated: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                                 \
    }                                                                                               \
  } while (false)
