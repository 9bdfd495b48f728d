// Graded test for lab07.4 (with 07.2 and 07.3): the primal-dual solve and the
// Schur-complement solve are two ways of solving the same linear system, so
// they must give the same v_new and λ up to round-off.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "constrained.h"
#include "scenes_for_tests.h"
#include "step.h"

using Catch::Matchers::WithinAbs;

TEST_CASE("KKT and Schur give the same v_new and lambda to 1e-9 on random scenes", "[lab07][pts=3]") {
  // Hard spanning trees (full row rank) plus soft extra springs of 1e-3 … 1e8
  // N/m; mass ratios up to 100; Δt from 1 ms to 0.1 s. The tolerance is
  // 1e-9 relative to the largest entry (or 1e-9 absolute when that is below 1).
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
    const cl::lab07::StepSolution kkt = cl::lab07::solve_kkt(cl::lab07::kkt_system(step), step.velocity.size());
    const cl::lab07::StepSolution schur = cl::lab07::solve_schur(step);
    CAPTURE(kkt.problem, schur.problem);
    REQUIRE(kkt.ok);
    REQUIRE(schur.ok);
    REQUIRE(kkt.velocity.size() == step.velocity.size());
    REQUIRE(schur.velocity.size() == step.velocity.size());
    REQUIRE(kkt.lambda.size() == step.phi.size());
    REQUIRE(schur.lambda.size() == step.phi.size());

    // (An empty v_new: every particle pinned; maxCoeff of nothing is undefined.)
    const double v_scale =
        std::max(1.0, schur.velocity.size() > 0 ? schur.velocity.cwiseAbs().maxCoeff() : 0.0);
    const lab07_test::Difference dv = lab07_test::largest_difference(kkt.velocity, schur.velocity);
    CAPTURE(dv.index, v_scale);
    REQUIRE_THAT(dv.value, WithinAbs(0.0, 1e-9 * v_scale));
    if (step.phi.size() > 0) {
      const double lambda_scale = std::max(1.0, schur.lambda.cwiseAbs().maxCoeff());
      const lab07_test::Difference dl = lab07_test::largest_difference(kkt.lambda, schur.lambda);
      CAPTURE(dl.index, lambda_scale);
      REQUIRE_THAT(dl.value, WithinAbs(0.0, 1e-9 * lambda_scale));
    }
    ++compared;
  }
  CHECK(compared == 12);
}
