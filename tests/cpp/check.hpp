#pragma once
// A minimal check harness for the C++ unit tests: each test executable returns non-zero when a
// check fails, and ctest reports it.
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace morphomap_test {
inline int& failures() {
  static int count = 0;
  return count;
}
}  // namespace morphomap_test

#define CHECK(cond)                                                                 \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "%s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond); \
      ++morphomap_test::failures();                                                 \
    }                                                                               \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                                                 \
  do {                                                                                                        \
    const double va_ = (a), vb_ = (b);                                                                        \
    if (!(std::abs(va_ - vb_) <= (tol))) {                                                                    \
      std::fprintf(stderr, "%s:%d: |%s - %s| = |%.17g - %.17g| > %g\n", __FILE__, __LINE__, #a, #b, va_, vb_, \
                   static_cast<double>(tol));                                                                 \
      ++morphomap_test::failures();                                                                           \
    }                                                                                                         \
  } while (0)

#define CHECK_THROWS(expr, type)                                                              \
  do {                                                                                        \
    bool thrown_ = false;                                                                     \
    try {                                                                                     \
      (void)(expr);                                                                           \
    } catch (const type&) {                                                                   \
      thrown_ = true;                                                                         \
    }                                                                                         \
    if (!thrown_) {                                                                           \
      std::fprintf(stderr, "%s:%d: %s did not throw %s\n", __FILE__, __LINE__, #expr, #type); \
      ++morphomap_test::failures();                                                           \
    }                                                                                         \
  } while (0)

#define TEST_MAIN_END() return morphomap_test::failures() == 0 ? EXIT_SUCCESS : EXIT_FAILURE
