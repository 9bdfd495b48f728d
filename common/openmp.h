#pragma once
// OpenMP's thread count for code that may be built without OpenMP (Apple's
// clang without Homebrew's libomp, docs/DESIGN.md §1): the pragmas are then
// ignored and every loop runs on the calling thread. Inline, so that each
// caller follows its own compile flags (common/ itself is built without OpenMP).
#ifdef _OPENMP
#include <omp.h>
#endif

namespace cl {

// Whether this file's caller was compiled with OpenMP.
constexpr bool openmp_enabled() {
#ifdef _OPENMP
  return true;
#else
  return false;
#endif
}

// The threads the next parallel region gets (1 without OpenMP).
inline int openmp_max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// Sets the threads of the next parallel regions (without OpenMP: nothing to set).
inline void set_openmp_threads(int threads) {
#ifdef _OPENMP
  omp_set_num_threads(threads);
#else
  (void)threads;
#endif
}

}  // namespace cl
