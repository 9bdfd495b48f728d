// Hidden graded test for lab06.1–06.4 (run only by the Gradescope bundle,
// shown to the student after grades are published): a local-global iteration
// does not care how the scene is turned or where it is.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "projective_dynamics.h"
#include "test_scenes.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;

TEST_CASE("a local-global iteration of a turned and moved scene is the turned and moved iteration",
          "[lab06][pts=1][hidden]") {
  // Turn the prediction y and the current x by R and move both by t, pinned
  // particles included: every projection d_e turns by R, and the global
  // step's minimiser turns and moves with them (A has the same entries; a
  // common shift is absorbed by the inertia term and the pinned ends alike).
  std::mt19937_64 rng(606);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 8;
    cl::Particles particles = lab06_test::random_particles(rng, n);
    particles.inv_mass[trial % n] = 0.0;
    const std::vector<cl::Spring> springs = lab06_test::random_springs(rng, particles.x, 6, 0.5, 1.5, 0.0, 4.0);
    const double dt = trial % 2 == 0 ? 1.0 / 60.0 : 0.2;
    const cl::lab06::Problem problem = cl::lab06::make_problem(particles.inv_mass, springs, dt);
    const Matrix3Xd y = particles.x + Matrix3Xd::NullaryExpr(3, n, [&]() { return 0.1 * unit(rng); });
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(3.0 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(3.0 * unit(rng), 3.0 * unit(rng), 3.0 * unit(rng));
    CAPTURE(trial, dt, particles.x, y, particles.inv_mass.transpose(), rotation, shift.transpose());
    cl::SpdFactorization factor;
    REQUIRE(factor.factor(cl::lab06::system_matrix(problem)));
    auto iterate = [&](const Matrix3Xd& x, const Matrix3Xd& prediction) {
      return cl::lab06::global_step(problem, factor, prediction, cl::lab06::local_step(x, springs));
    };
    const Matrix3Xd plain = iterate(particles.x, y);
    const Matrix3Xd turned =
        iterate((rotation * particles.x).colwise() + shift, (rotation * y).colwise() + shift);
    const Matrix3Xd expected = (rotation * plain).colwise() + shift;
    REQUIRE(cl::test::near(turned, expected, 1e-10 * (1.0 + plain.cwiseAbs().maxCoeff()), "particle"));
  }
}
