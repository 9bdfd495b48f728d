// Graded tests for lab06.3 and lab06.4 (right_hand_side, global_step) and
// lab06.5 (objective).
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "projective_dynamics.h"
#include "test_scenes.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

TEST_CASE("the global step minimises the inertia plus the springs pulled toward fixed projections",
          "[lab06][pts=2]") {
  // With d fixed, q(x) = Σ m‖x − y‖²/(2Δt²) + Σ k/2 ‖(x_i − x_j) − d_e‖² is a
  // convex quadratic: its minimiser is where its gradient over the movable
  // particles vanishes. The gradient is written out here, independent of A and b.
  std::mt19937_64 rng(63);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 7;
    cl::Particles particles = lab06_test::random_particles(rng, n);
    particles.inv_mass[trial % n] = 0.0;
    if (trial % 3 == 0) particles.inv_mass[(trial + 3) % n] = 0.0;
    std::vector<cl::Spring> springs = lab06_test::random_springs(rng, particles.x, 8, 0.5, 1.5, 0.0, 4.0);
    springs.push_back({(trial + 3) % n, trial % n, 0.3, 50.0});  // both ends pinned when trial % 3 == 0
    const double dt = trial % 2 == 0 ? 1.0 / 60.0 : 0.2;
    const cl::lab06::Problem problem = cl::lab06::make_problem(particles.inv_mass, springs, dt);
    const Matrix3Xd y = particles.x + Matrix3Xd::NullaryExpr(3, n, [&]() { return 0.1 * unit(rng); });
    const Matrix3Xd d = Matrix3Xd::NullaryExpr(3, static_cast<Eigen::Index>(springs.size()),
                                               [&]() { return unit(rng); });  // any vectors will do
    CAPTURE(trial, dt, particles.inv_mass.transpose(), y, d);

    cl::SpdFactorization factor;
    REQUIRE(factor.factor(cl::lab06::system_matrix(problem)));
    const Matrix3Xd x = cl::lab06::global_step(problem, factor, y, d);
    REQUIRE(x.cols() == n);
    Matrix3Xd gradient = Matrix3Xd::Zero(3, n);
    Eigen::VectorXd scale = Eigen::VectorXd::Zero(n);  // magnitudes of the terms, for the tolerance
    for (int p = 0; p < n; ++p) {
      if (particles.inv_mass[p] == 0.0) continue;
      const Vector3d inertia = (x.col(p) - y.col(p)) / (particles.inv_mass[p] * dt * dt);
      gradient.col(p) += inertia;
      scale[p] += (x.col(p).norm() + y.col(p).norm()) / (particles.inv_mass[p] * dt * dt);
    }
    for (std::size_t e = 0; e < springs.size(); ++e) {
      const cl::Spring& spring = springs[e];
      const Vector3d pull =
          spring.stiffness * (x.col(spring.i) - x.col(spring.j) - d.col(static_cast<Eigen::Index>(e)));
      gradient.col(spring.i) += pull;
      gradient.col(spring.j) -= pull;
      const double size =
          spring.stiffness * (x.col(spring.i).norm() + x.col(spring.j).norm() + d.col(static_cast<Eigen::Index>(e)).norm());
      scale[spring.i] += size;
      scale[spring.j] += size;
    }
    for (int p = 0; p < n; ++p) {
      CAPTURE(p, x.col(p).transpose());
      if (particles.inv_mass[p] == 0.0) {
        REQUIRE(x.col(p) == y.col(p));  // a pinned particle stays where it is held
      } else {
        const std::string where = "|gradient| at particle " + std::to_string(p);
        const double tol = 1e-12 * scale[p];
        REQUIRE(cl::test::near(gradient.col(p).norm(), 0.0, tol, where));
      }
    }
    // The right-hand side alone: A x = b at the minimiser.
    const cl::RowsX3 b = cl::lab06::right_hand_side(problem, y, d);
    const cl::RowsX3 rows = cl::gather_rows(x, problem.map);
    const cl::RowsX3 residual = cl::lab06::system_matrix(problem) * rows - b;
    REQUIRE(cl::test::near(Eigen::MatrixXd(residual), Eigen::MatrixXd::Zero(residual.rows(), 3), 1e-12 * scale.maxCoeff()));
  }
  // A missing or wrong-sized factorization, or mis-sized y and d, are bad arguments.
  Eigen::VectorXd inv_mass(3);
  inv_mass << 0.0, 1.0, 1.0;
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, {{0, 1, 1.0, 10.0}, {1, 2, 1.0, 10.0}}, 0.01);
  const Matrix3Xd y = Matrix3Xd::Random(3, 3);
  const Matrix3Xd d = Matrix3Xd::Random(3, 2);
  cl::SpdFactorization none;
  REQUIRE_THROWS_AS(cl::lab06::global_step(problem, none, y, d), std::invalid_argument);
  cl::SpdFactorization wrong_size;
  REQUIRE(wrong_size.factor(cl::assemble(3, 3, {{0, 0, 1.0}, {1, 1, 1.0}, {2, 2, 1.0}})));
  REQUIRE_THROWS_AS(cl::lab06::global_step(problem, wrong_size, y, d), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab06::right_hand_side(problem, Matrix3Xd::Random(3, 2), d), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab06::right_hand_side(problem, y, Matrix3Xd::Random(3, 3)), std::invalid_argument);
}

TEST_CASE("the objective is the inertia of the movable particles plus the spring energy", "[lab06][pts=1]") {
  // By hand: particle 0 pinned (its y is far away and must not count),
  // particle 1 of 2 kg moved 0.1 m from y: 2 · 0.01 / (2 · 0.01) = 1 J;
  // spring 0-1 of 10 N/m, rest 4, length 5: 10/2 · 1² = 5 J;
  // spring 1-2 of 3 N/m, rest 0, length 2: 3/2 · 2² = 6 J.  g = 12 J.
  Eigen::VectorXd inv_mass(3);
  inv_mass << 0.0, 0.5, 2.0;
  const double dt = 0.1;
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, {{0, 1, 4.0, 10.0}, {1, 2, 0.0, 3.0}}, dt);
  Matrix3Xd x(3, 3), y(3, 3);
  x << 0, 3, 3,  //
      0, 4, 4,   //
      0, 0, 2;
  y = x;
  y.col(0) = Vector3d(5.0, 5.0, 5.0);
  y(2, 1) = 0.1;
  CAPTURE(x, y);
  REQUIRE(cl::test::near_rel(cl::lab06::objective(problem, x, y), 12.0, 1e-14));
  // At x = y only the springs count; with no springs only the inertia.
  REQUIRE(cl::test::near_rel(cl::lab06::objective(problem, x, x), 11.0, 1e-14));
  const cl::lab06::Problem loose = cl::lab06::make_problem(inv_mass, {}, dt);
  REQUIRE(cl::test::near_rel(cl::lab06::objective(loose, x, y), 1.0, 1e-14));
  REQUIRE_THROWS_AS(cl::lab06::objective(problem, Matrix3Xd::Zero(3, 2), y), std::invalid_argument);
}
