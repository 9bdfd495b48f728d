// Graded tests of lab12.1: the vertex's force and 3 × 3 block are lab 06's
// gradient and clamped Hessian, restricted to the vertex.
#include <random>

#include <Eigen/Eigenvalues>
#include "tests/support/catch.h"

#include "scenes.h"
#include "simulation.h"
#include "tests/support/checks.h"
#include "vbd.h"

TEST_CASE("the vertex block is lab 06's gradient block (negated) and its clamped diagonal Hessian block",
          "[lab12][pts=2]") {
  // Stretched and compressed springs alike (rest lengths 0.5 to 2 times the
  // current length): the compressed ones are where the clamp acts.
  std::mt19937_64 rng(1201);
  for (int trial = 0; trial < 6; ++trial) {
    cl::Particles start = lab12_test::random_particles(rng, 9);
    start.inv_mass[trial] = 0.0;
    const std::vector<cl::Spring> springs = lab12_test::random_springs(rng, start.x, 10, 0.5, 2.0, 0.0, 4.0);
    const double dt = trial % 2 ? 1.0 / 60.0 : 0.2;
    const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, springs, dt);
    const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(9, springs);
    const Eigen::Matrix3Xd y = cl::lab06::predict(start, Eigen::Vector3d(0.0, -9.81, 0.0), dt);
    const Eigen::Matrix3Xd& x = start.x;
    CAPTURE(trial, dt, start.x, start.v, start.inv_mass.transpose());
    const Eigen::VectorXd gradient = cl::lab06::newton_gradient(problem, x, y);
    const Eigen::MatrixXd hessian = Eigen::MatrixXd(cl::lab06::newton_hessian(problem, x, true));
    for (int u = 0; u < problem.map.unknowns(); ++u) {
      const int p = problem.map.particle_of[static_cast<std::size_t>(u)];
      CAPTURE(trial, p);
      const cl::lab12::VertexBlock block = cl::lab12::vertex_block(problem, adjacency, x, y, p);
      const double scale = gradient.cwiseAbs().maxCoeff() + 1.0;
      REQUIRE(cl::test::near(block.force, Eigen::Vector3d(-gradient.segment<3>(3 * u)), 1e-12 * scale));
      const Eigen::Matrix3d expected = hessian.block<3, 3>(3 * u, 3 * u);
      REQUIRE(cl::test::near(block.hessian, expected, 1e-12 * expected.cwiseAbs().maxCoeff()));
      // Positive definite: the clamp leaves no negative eigenvalue.
      const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block.hessian).eigenvalues();
      REQUIRE(cl::test::at_least("smallest eigenvalue", eigenvalues.minCoeff(), 0.0));
    }
  }
}

TEST_CASE("a pinned vertex gets only its springs; coincident ends and a zero-rest spring stay finite", "[lab12][pts=1]") {
  const double k = 250.0, dt = 0.05;
  Eigen::VectorXd inv_mass(3);
  inv_mass << 0.0, 2.0, 0.5;
  // 0–1 coincident with rest 0.3; 1–2 zero rest length.
  const std::vector<cl::Spring> springs{{0, 1, 0.3, k}, {1, 2, 0.0, k}};
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, springs, dt);
  const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(3, springs);
  Eigen::Matrix3Xd x(3, 3);
  x << 0.0, 0.0, 0.4, 0.0, 0.0, -0.3, 0.0, 0.0, 0.0;
  const Eigen::Matrix3Xd y = x;
  // Vertex 1: inertia 0 (x = y); it is the coincident spring's end j, pushed
  // along −x (n = (1, 0, 0) is the direction of x_0 − x_1) with k L, and the
  // spring adds k n nᵀ (across term 0); the zero-rest spring pulls it toward 2
  // with −k (x_1 − x_2) and adds k I.
  const cl::lab12::VertexBlock one = cl::lab12::vertex_block(problem, adjacency, x, y, 1);
  const Eigen::Vector3d expected_force = -k * 0.3 * Eigen::Vector3d::UnitX() - k * (x.col(1) - x.col(2));
  REQUIRE(cl::test::near(one.force, expected_force, 1e-12 * k));
  Eigen::Matrix3d expected = (1.0 / (inv_mass[1] * dt * dt) + k) * Eigen::Matrix3d::Identity();
  expected(0, 0) += k;
  REQUIRE(cl::test::near(one.hessian, expected, 1e-12 * k));
  // The pinned vertex 0 (end i): no inertia term, pushed along +x.
  const cl::lab12::VertexBlock zero = cl::lab12::vertex_block(problem, adjacency, x, y, 0);
  REQUIRE(cl::test::near(zero.force, Eigen::Vector3d(k * 0.3, 0.0, 0.0), 1e-12 * k));
  Eigen::Matrix3d pinned = Eigen::Matrix3d::Zero();
  pinned(0, 0) = k;
  REQUIRE(cl::test::near(zero.hessian, pinned, 1e-12 * k));
  REQUIRE_THROWS_AS(cl::lab12::vertex_block(problem, adjacency, x, y, 3), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab12::vertex_block(problem, adjacency, Eigen::Matrix3Xd(3, 2), y, 1), std::invalid_argument);
}
