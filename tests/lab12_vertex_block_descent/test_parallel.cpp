// Graded test of lab12.5's OpenMP loop: the handout asks for a colour-parallel
// sweep, and a sweep without its pragma gives the same bits (the test of one
// and two threads cannot tell), so this case counts the parallel regions the
// sweep opens. GCC turns `#pragma omp parallel` (and `parallel for`) into a
// call of libgomp's GOMP_parallel*; this program defines those entry points,
// counts each call and hands it on to libgomp's own (dlsym RTLD_NEXT), so
// every OpenMP region of the program still runs as it would.
#include <dlfcn.h>
#include <omp.h>

#include <atomic>
#include <vector>

#include "tests/support/catch.h"

#include "scenes.h"
#include "simulation.h"
#include "vbd.h"

namespace {
std::atomic<int> parallel_regions{0};

template <typename Function>
Function libgomp(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_NEXT, name));
}
}  // namespace

extern "C" {
void GOMP_parallel(void (*fn)(void*), void* data, unsigned threads, unsigned flags) {
  using Real = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const Real real = libgomp<Real>("GOMP_parallel");
  ++parallel_regions;
  real(fn, data, threads, flags);
}

// `parallel for` with a schedule other than static: one entry point per kind.
#define CL_COUNTED_PARALLEL_LOOP(NAME)                                                                     \
  void NAME(void (*fn)(void*), void* data, unsigned threads, long start, long end, long step, long chunk, \
            unsigned flags) {                                                                              \
    using Real = void (*)(void (*)(void*), void*, unsigned, long, long, long, long, unsigned);             \
    static const Real real = libgomp<Real>(#NAME);                                                         \
    ++parallel_regions;                                                                                    \
    real(fn, data, threads, start, end, step, chunk, flags);                                               \
  }
CL_COUNTED_PARALLEL_LOOP(GOMP_parallel_loop_static)
CL_COUNTED_PARALLEL_LOOP(GOMP_parallel_loop_dynamic)
CL_COUNTED_PARALLEL_LOOP(GOMP_parallel_loop_guided)
CL_COUNTED_PARALLEL_LOOP(GOMP_parallel_loop_nonmonotonic_dynamic)
CL_COUNTED_PARALLEL_LOOP(GOMP_parallel_loop_nonmonotonic_guided)
#undef CL_COUNTED_PARALLEL_LOOP

#define CL_COUNTED_PARALLEL_RUNTIME(NAME)                                                                  \
  void NAME(void (*fn)(void*), void* data, unsigned threads, long start, long end, long step,              \
            unsigned flags) {                                                                              \
    using Real = void (*)(void (*)(void*), void*, unsigned, long, long, long, unsigned);                   \
    static const Real real = libgomp<Real>(#NAME);                                                         \
    ++parallel_regions;                                                                                    \
    real(fn, data, threads, start, end, step, flags);                                                      \
  }
CL_COUNTED_PARALLEL_RUNTIME(GOMP_parallel_loop_runtime)
CL_COUNTED_PARALLEL_RUNTIME(GOMP_parallel_loop_nonmonotonic_runtime)
CL_COUNTED_PARALLEL_RUNTIME(GOMP_parallel_loop_maybe_nonmonotonic_runtime)
#undef CL_COUNTED_PARALLEL_RUNTIME
}

TEST_CASE("the coloured sweep runs its colours in OpenMP parallel regions on two threads", "[lab12][pts=1]") {
  // A 12 x 12 cloth, top row pinned, with a prediction 2 cm below its start;
  // every free particle its own colour (a valid colouring needing no lab12.4).
  const int n = 12;
  const double h = 1.0 / (n - 1);
  const std::vector<cl::Spring> springs = lab12_test::grid_springs(n, n, h, 1e3, true);
  Eigen::VectorXd inv_mass = Eigen::VectorXd::Constant(n * n, static_cast<double>(n * n));
  inv_mass.head(n).setZero();
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, springs, 1.0 / 60.0);
  const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(n * n, springs);
  std::vector<std::vector<int>> groups;
  for (int p = n; p < n * n; ++p) groups.push_back({p});
  Eigen::Matrix3Xd x = lab12_test::grid_positions(n, n, h);
  Eigen::Matrix3Xd y = x;
  y.row(1).array() -= 0.02;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(2);
  parallel_regions = 0;
  cl::lab12::vbd_sweep(problem, adjacency, groups, y, x);
  const int counted = parallel_regions;
  omp_set_num_threads(saved);
  CAPTURE(counted);
  INFO("the sweep opened " << counted << " OpenMP parallel regions with 2 threads; expected at least one "
       "(a #pragma omp parallel, or parallel for, over each colour's vertices)");
  CHECK(counted >= 1);
}
