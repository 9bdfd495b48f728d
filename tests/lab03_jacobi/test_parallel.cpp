// Graded test of lab03.1's OpenMP loop: the handout asks for a parallel loop
// over the particles, and a sweep without its pragma gives the same bits (the
// test of one and two threads cannot tell), so this case counts the parallel
// regions the sweep opens (tests/support/openmp_regions.h: under GCC's and
// LLVM's runtimes alike). Lab 12's test_parallel.cpp does the same for its
// coloured sweep.
#include "tests/support/catch.h"

#include "common/openmp.h"
#include "common/scene.h"
#include "jacobi.h"
#include "tests/support/openmp_regions.h"

TEST_CASE("the sweep runs its loop over the particles in an OpenMP parallel region on two threads",
          "[lab03][pts=1][openmp]") {
  // A 16 x 16 cloth with its top corners pinned, its free particles 2 cm below their rest state.
  const cl::Scene scene = cl::parse_scene(R"({"cloth": {"nx": 16, "pin": ["top-left", "top-right"]}})", "cloth.json");
  Eigen::Matrix3Xd x = scene.particles.x;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    if (scene.particles.inv_mass[p] > 0.0) x(1, p) -= 0.02;
  }
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(x.cols(), scene.springs);
  Eigen::Matrix3Xd x_next;
  if (!cl::test::openmp_regions_counted()) CL_SKIP("built without OpenMP: no parallel region to count");
  const int saved = cl::openmp_max_threads();
  cl::set_openmp_threads(2);
  cl::test::openmp_regions = 0;
  cl::lab03::jacobi_sweep(x, x_next, scene.particles.inv_mass, scene.springs, incidence, 1.0,
                          cl::lab03::Averaging::kByCount);
  const int counted = cl::test::openmp_regions;
  cl::set_openmp_threads(saved);
  CAPTURE(counted);
  INFO("the sweep opened " << counted << " OpenMP parallel regions with 2 threads; expected at least one "
       "(a #pragma omp parallel for over the particles)");
  CHECK(counted >= 1);
}
