// Graded tests for lab13.3: the warm start λ⁰.
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "tests/support/catch.h"

#include "constrained_newton.h"
#include "lab13_scenes.h"
#include "tests/support/checks.h"

using cl::lab13::Warm;
using cl::test::near;

TEST_CASE("warm start carries the forces the springs hold at the start", "[lab13][pts=2]") {
  const double inf = std::numeric_limits<double>::infinity();
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    lab13_test::RandomScene scene = lab13_test::random_scene(rng, 3 + static_cast<int>(seed % 5), 1, 2, 1.0);
    std::uniform_real_distribution<double> exponent(0.0, 8.0);
    for (std::size_t e = 0; e < scene.springs.size(); ++e) {
      scene.springs[e].stiffness = e % 3 == 2 ? inf : std::pow(10.0, exponent(rng));
    }
    CAPTURE(scene.text);
    const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
    const Eigen::VectorXd previous = Eigen::VectorXd::LinSpaced(m, -3.0, 2.0);
    const Eigen::VectorXd forces = cl::lab13::warm_start(scene.particles.x, scene.springs, previous, Warm::kForces);
    const Eigen::VectorXd fresh = cl::lab13::warm_start(scene.particles.x, scene.springs, Eigen::VectorXd(), Warm::kForces);
    const Eigen::VectorXd zero = cl::lab13::warm_start(scene.particles.x, scene.springs, previous, Warm::kZero);
    REQUIRE(forces.size() == m);
    REQUIRE(fresh.size() == m);
    REQUIRE(zero.size() == m);
    for (Eigen::Index e = 0; e < m; ++e) {
      CAPTURE(e);
      const cl::Spring& s = scene.springs[static_cast<std::size_t>(e)];
      const double phi = (scene.particles.x.col(s.i) - scene.particles.x.col(s.j)).norm() - s.rest_length;
      if (std::isfinite(s.stiffness)) {
        CHECK(cl::test::near_rel(forces[e], -s.stiffness * phi, 1e-12, "finite spring: -k phi"));
        CHECK(cl::test::near_rel(fresh[e], -s.stiffness * phi, 1e-12, "finite spring without a previous step"));
      } else {
        CHECK(near(forces[e], previous[e], 0.0, "hard spring: the previous step's lambda"));
        CHECK(near(fresh[e], 0.0, 0.0, "hard spring without a previous step: 0"));
      }
      CHECK(near(zero[e], 0.0, 0.0, "Warm::kZero"));
    }
  }
}

TEST_CASE("warm start refuses a previous lambda of the wrong size or not finite", "[lab13][pts=1]") {
  std::mt19937_64 rng(7);
  const lab13_test::RandomScene scene = lab13_test::random_scene(rng, 4, 1, 1, 10.0);
  const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
  CHECK_THROWS_AS(cl::lab13::warm_start(scene.particles.x, scene.springs, Eigen::VectorXd::Zero(m + 1), Warm::kForces),
                  std::invalid_argument);
  Eigen::VectorXd bad = Eigen::VectorXd::Zero(m);
  bad[0] = std::nan("");
  CHECK_THROWS_AS(cl::lab13::warm_start(scene.particles.x, scene.springs, bad, Warm::kForces), std::invalid_argument);
  std::vector<cl::Spring> outside = scene.springs;
  outside[0].j = 99;
  CHECK_THROWS_AS(cl::lab13::warm_start(scene.particles.x, outside, Eigen::VectorXd(), Warm::kForces),
                  std::invalid_argument);
}
