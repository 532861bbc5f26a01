// Problem sizes for the slow tests. The release run uses the full sizes; the
// sanitizer run (scripts/test.sh sets SOUPUV_TEST_SIZE=reduced there, where
// everything runs several times slower) uses smaller ones that still walk the
// same code — the SIMD kernels, the padded arrays, the threads — and skips
// the tests that only measure scale or accuracy at scale.
#pragma once

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace soupuv::testing {

inline bool reduced_test_size() {
  const char* v = std::getenv("SOUPUV_TEST_SIZE");
  return v && std::strcmp(v, "reduced") == 0;
}

// `full` in the release run, `reduced` under SOUPUV_TEST_SIZE=reduced.
template <class T>
T test_size(T full, T reduced) {
  return reduced_test_size() ? reduced : full;
}

}  // namespace soupuv::testing

// First statement of a test that only measures scale (or accuracy at a size
// the reduced run cannot afford): skipped under SOUPUV_TEST_SIZE=reduced.
#define SOUPUV_SKIP_IF_REDUCED(why)                                          \
  do {                                                                      \
    if (::soupuv::testing::reduced_test_size()) GTEST_SKIP() << "reduced size: " << (why); \
  } while (0)
