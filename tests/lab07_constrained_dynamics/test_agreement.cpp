// Graded tests for lab07.3 and lab07.4: each solve against a dense solve of
// the KKT system that the test writes out itself (scenes_for_tests.h), so a
// mistake in kkt_system (lab07.2) costs nothing here and a mistake in one
// solve is charged to that solve's task alone.
#include <algorithm>
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "constrained.h"
#include "scenes_for_tests.h"
#include "step.h"
#include "tests/support/checks.h"

namespace {

// Hard spanning trees (full row rank) plus soft extra springs of 1e-3 … 1e8
// N/m; mass ratios up to 100; Δt from 1 ms to 0.1 s. `solve` is one of the two
// solves; the tolerance is 1e-9 relative to the largest entry of the expected
// v_new or λ (or 1e-9 absolute when that is below 1).
template <typename Solve>
void check_against_dense(Solve solve) {
  int compared = 0;
  for (std::uint64_t seed = 100; seed < 112; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> size(2, 25);
    const int n = size(rng);
    const int pinned = static_cast<int>(seed % 3);
    const int extra = static_cast<int>(seed % 4) * n / 2;
    const lab07_test::RandomScene scene = lab07_test::random_scene(rng, n, pinned, extra, seed % 5 != 4);
    const double dts[] = {1e-3, 1.0 / 60.0, 0.1};
    cl::lab07::StepSettings settings;
    settings.dt = dts[seed % 3];
    settings.gravity = Eigen::Vector3d(0.3, -9.81, -0.2);
    CAPTURE(seed, n, pinned, extra, settings.dt, scene.text);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const cl::lab07::LinearizedStep step = cl::lab07::linearize(scene.particles, scene.springs, map, settings);
    const cl::lab07::StepSolution expected = lab07_test::dense_kkt_solve(step);
    REQUIRE(cl::test::solved(expected));
    const cl::lab07::StepSolution actual = solve(step);
    REQUIRE(cl::test::solved(actual));
    const double v_scale =
        std::max(1.0, expected.velocity.size() > 0 ? expected.velocity.cwiseAbs().maxCoeff() : 0.0);
    REQUIRE(cl::test::near(actual.velocity, expected.velocity, 1e-9 * v_scale, "v_new (stacked)"));
    const double lambda_scale = std::max(1.0, expected.lambda.size() > 0 ? expected.lambda.cwiseAbs().maxCoeff() : 0.0);
    REQUIRE(cl::test::near(actual.lambda, expected.lambda, 1e-9 * lambda_scale, "lambda (one per spring)"));
    ++compared;
  }
  CHECK(compared == 12);
}

}  // namespace

TEST_CASE("solve_kkt gives the v_new and lambda of a dense solve of the KKT system to 1e-9 on random scenes",
          "[lab07][pts=1]") {
  check_against_dense([](const cl::lab07::LinearizedStep& step) {
    return cl::lab07::solve_kkt(lab07_test::sparse_kkt(step), step.velocity.size());
  });
}

TEST_CASE("the Schur solve gives the v_new and lambda of a dense solve of the KKT system to 1e-9 on random scenes",
          "[lab07][pts=2]") {
  check_against_dense([](const cl::lab07::LinearizedStep& step) { return cl::lab07::solve_schur(step); });
}
