// Graded test of lab12.5's OpenMP loop: the handout asks for a colour-parallel
// sweep, and a sweep without its pragma gives the same bits (the test of one
// and two threads cannot tell), so this case counts the parallel regions the
// sweep opens (tests/support/openmp_regions.h: under GCC's and LLVM's runtimes
// alike).
#include <vector>

#include "tests/support/catch.h"

#include "common/openmp.h"
#include "scenes.h"
#include "simulation.h"
#include "tests/support/openmp_regions.h"
#include "vbd.h"

TEST_CASE("the coloured sweep runs its colours in OpenMP parallel regions on two threads", "[lab12][pts=1][openmp]") {
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
  if (!cl::test::openmp_regions_counted()) CL_SKIP("built without OpenMP: no parallel region to count");
  const int saved = cl::openmp_max_threads();
  cl::set_openmp_threads(2);
  cl::test::openmp_regions = 0;
  cl::lab12::vbd_sweep(problem, adjacency, groups, y, x);
  const int counted = cl::test::openmp_regions;
  cl::set_openmp_threads(saved);
  CAPTURE(counted);
  INFO("the sweep opened " << counted << " OpenMP parallel regions with 2 threads; expected at least one "
       "(a #pragma omp parallel, or parallel for, over each colour's vertices)");
  CHECK(counted >= 1);
}
