// Hidden graded test for lab08.2 (run only by the Gradescope bundle, shown to
// the student after grades are published): an XPBD step does not care how the
// scene is turned or where it is.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "tests/support/checks.h"
#include "xpbd.h"

TEST_CASE("an XPBD step of a turned and moved chain is the turned and moved step with the same lambda",
          "[lab08][pts=1][hidden]") {
  // Turn positions, velocities and gravity by R and move the positions by t:
  // every C and α̃ is unchanged, so x' = R x + t, v' = R v, and λ is the same.
  std::mt19937_64 rng(808);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 4 + trial % 5;
    cl::Particles particles;
    particles.x.resize(3, n);
    particles.v.resize(3, n);
    particles.inv_mass.resize(n);
    std::vector<cl::Spring> springs;
    for (int p = 0; p < n; ++p) {
      particles.x.col(p) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      particles.v.col(p) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      particles.inv_mass[p] = p == 0 ? 0.0 : std::pow(10.0, unit(rng));
      if (p > 0) {
        const double length = (particles.x.col(p) - particles.x.col(p - 1)).norm();
        springs.push_back({p - 1, p, (1.0 + 0.2 * unit(rng)) * length,
                           trial % 3 == 0 ? cl::kInfiniteStiffness : std::pow(10.0, 1.0 + 3.0 * (unit(rng) + 1.0))});
      }
    }
    springs.push_back({0, n - 1, (particles.x.col(0) - particles.x.col(n - 1)).norm(), 500.0});
    const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(n, springs);
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(3.0 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(2.0 * unit(rng), 2.0 * unit(rng), 2.0 * unit(rng));
    cl::lab08::XpbdSettings settings;
    settings.dt = trial % 2 == 0 ? 1.0 / 60.0 : 0.05;
    settings.iterations = 1 + trial;
    cl::lab08::XpbdSettings turned_settings = settings;
    turned_settings.gravity = rotation * settings.gravity;
    cl::Particles turned = particles;
    turned.x = (rotation * particles.x).colwise() + shift;
    turned.v = rotation * particles.v;
    CAPTURE(trial, particles.x, particles.v, particles.inv_mass.transpose(), rotation, shift.transpose(),
            settings.dt, settings.iterations);
    Eigen::VectorXd lambda, turned_lambda;
    cl::lab08::xpbd_step(particles, constraints, settings, lambda);
    cl::lab08::xpbd_step(turned, constraints, turned_settings, turned_lambda);
    const Eigen::Matrix3Xd expected_x = (rotation * particles.x).colwise() + shift;
    const Eigen::Matrix3Xd expected_v = rotation * particles.v;
    REQUIRE(cl::test::near(turned.x, expected_x, 1e-11, "particle"));
    REQUIRE(cl::test::near(turned.v, expected_v, 1e-11 / settings.dt, "particle"));
    const double lambda_scale = 1.0 + lambda.cwiseAbs().maxCoeff();
    REQUIRE(cl::test::near(turned_lambda, lambda, 1e-10 * lambda_scale, "lambda (one per spring)"));
  }
}
