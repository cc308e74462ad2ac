// Property checks inside fuzz targets: a violated property is a finding, so
// it aborts like a crash and libFuzzer saves the input.
#pragma once

#include <cstdio>
#include <cstdlib>

#define TONUS_FUZZ_CHECK(cond)                                                                 \
  do {                                                                                         \
    if (!(cond)) {                                                                             \
      std::fprintf(stderr, "fuzz property violated: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
      std::abort();                                                                            \
    }                                                                                          \
  } while (0)
