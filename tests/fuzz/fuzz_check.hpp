#pragma once
// A property a fuzz target checks on every input: a violation aborts, so libFuzzer stores the
// input as a crash. Unlike assert() it stays on in every build type.
#include <cstdio>
#include <cstdlib>

#define NIDEVO_FUZZ_CHECK(condition)                                                          \
  do {                                                                                        \
    if (!(condition)) {                                                                       \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                           \
    }                                                                                         \
  } while (0)
