// Graded test of lab03.1's OpenMP loop: the handout asks for a parallel loop
// over the particles, and a sweep without its pragma gives the same bits (the
// test of one and two threads cannot tell), so this case counts the parallel
// regions the sweep opens. GCC turns `#pragma omp parallel for` (and
// `parallel`) into a call of libgomp's GOMP_parallel*; this program defines
// those entry points, counts each call and hands it on to libgomp's own
// (dlsym RTLD_NEXT), so every OpenMP region of the program still runs as it
// would. (Lab 12's test_parallel.cpp does the same for its coloured sweep.)
#include <dlfcn.h>
#include <omp.h>

#include <atomic>
#include <vector>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "jacobi.h"

namespace {
std::atomic<int> lab03_parallel_regions{0};

template <typename Function>
Function lab03_libgomp(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_NEXT, name));
}
}  // namespace

extern "C" {
void GOMP_parallel(void (*fn)(void*), void* data, unsigned threads, unsigned flags) {
  using Real = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const Real real = lab03_libgomp<Real>("GOMP_parallel");
  ++lab03_parallel_regions;
  real(fn, data, threads, flags);
}

// `parallel for` with a schedule other than static: one entry point per kind.
#define CL_LAB03_COUNTED_LOOP(NAME)                                                                        \
  void NAME(void (*fn)(void*), void* data, unsigned threads, long start, long end, long step, long chunk, \
            unsigned flags) {                                                                              \
    using Real = void (*)(void (*)(void*), void*, unsigned, long, long, long, long, unsigned);             \
    static const Real real = lab03_libgomp<Real>(#NAME);                                                   \
    ++lab03_parallel_regions;                                                                              \
    real(fn, data, threads, start, end, step, chunk, flags);                                               \
  }
CL_LAB03_COUNTED_LOOP(GOMP_parallel_loop_static)
CL_LAB03_COUNTED_LOOP(GOMP_parallel_loop_dynamic)
CL_LAB03_COUNTED_LOOP(GOMP_parallel_loop_guided)
CL_LAB03_COUNTED_LOOP(GOMP_parallel_loop_nonmonotonic_dynamic)
CL_LAB03_COUNTED_LOOP(GOMP_parallel_loop_nonmonotonic_guided)
#undef CL_LAB03_COUNTED_LOOP

#define CL_LAB03_COUNTED_RUNTIME(NAME)                                                                     \
  void NAME(void (*fn)(void*), void* data, unsigned threads, long start, long end, long step,              \
            unsigned flags) {                                                                              \
    using Real = void (*)(void (*)(void*), void*, unsigned, long, long, long, unsigned);                   \
    static const Real real = lab03_libgomp<Real>(#NAME);                                                   \
    ++lab03_parallel_regions;                                                                              \
    real(fn, data, threads, start, end, step, flags);                                                      \
  }
CL_LAB03_COUNTED_RUNTIME(GOMP_parallel_loop_runtime)
CL_LAB03_COUNTED_RUNTIME(GOMP_parallel_loop_nonmonotonic_runtime)
CL_LAB03_COUNTED_RUNTIME(GOMP_parallel_loop_maybe_nonmonotonic_runtime)
#undef CL_LAB03_COUNTED_RUNTIME
}

TEST_CASE("the sweep runs its loop over the particles in an OpenMP parallel region on two threads",
          "[lab03][pts=1]") {
  // A 16 x 16 cloth with its top corners pinned, its free particles 2 cm below their rest state.
  const cl::Scene scene = cl::parse_scene(R"({"cloth": {"nx": 16, "pin": ["top-left", "top-right"]}})", "cloth.json");
  Eigen::Matrix3Xd x = scene.particles.x;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    if (scene.particles.inv_mass[p] > 0.0) x(1, p) -= 0.02;
  }
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(x.cols(), scene.springs);
  Eigen::Matrix3Xd x_next;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(2);
  lab03_parallel_regions = 0;
  cl::lab03::jacobi_sweep(x, x_next, scene.particles.inv_mass, scene.springs, incidence, 1.0,
                          cl::lab03::Averaging::kByCount);
  const int counted = lab03_parallel_regions;
  omp_set_num_threads(saved);
  CAPTURE(counted);
  INFO("the sweep opened " << counted << " OpenMP parallel regions with 2 threads; expected at least one "
       "(a #pragma omp parallel for over the particles)");
  CHECK(counted >= 1);
}
