// Graded test for lab06.2, system_matrix: A = M/Δt² + Σ k SᵀS over the unknowns.
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "projective_dynamics.h"
#include "tests/support/checks.h"


TEST_CASE("A equals a dense build on three particles and is symmetric positive definite", "[lab06][pts=2]") {
  std::mt19937_64 rng(62);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  // Every choice of pinned particles except "all three", several masses, stiffnesses and steps.
  const std::vector<std::vector<int>> pin_sets{{}, {0}, {1}, {2}, {0, 2}, {1, 2}};
  for (const std::vector<int>& pins : pin_sets) {
    for (int trial = 0; trial < 4; ++trial) {
      Eigen::VectorXd inv_mass(3);
      for (int p = 0; p < 3; ++p) inv_mass[p] = std::pow(10.0, 3.0 * unit(rng));
      for (const int p : pins) inv_mass[p] = 0.0;
      std::vector<cl::Spring> springs{{0, 1, 1.0, std::pow(10.0, 3.0 * unit(rng))},
                                      {2, 1, 0.5, std::pow(10.0, 3.0 * unit(rng))},
                                      {0, 2, 0.0, std::pow(10.0, 3.0 * unit(rng))}};
      if (trial == 3) springs.push_back({1, 0, 2.0, 7.0});  // a second spring on the same pair adds up
      const double dt = std::pow(10.0, -1.0 + unit(rng));
      const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, springs, dt);
      std::string spring_list;  // "i-j: k" per spring
      for (const cl::Spring& spring : springs) {
        spring_list += std::to_string(spring.i) + "-" + std::to_string(spring.j) + ": " +
                       std::to_string(spring.stiffness) + "; ";
      }
      CAPTURE(pins, trial, inv_mass.transpose(), dt, spring_list);

      // Dense build over all three particles, then the movable rows and columns.
      Eigen::Matrix3d full = Eigen::Matrix3d::Zero();
      for (int p = 0; p < 3; ++p) {
        if (inv_mass[p] > 0.0) full(p, p) = 1.0 / (inv_mass[p] * dt * dt);
      }
      for (const cl::Spring& spring : springs) {
        Eigen::Vector3d s = Eigen::Vector3d::Zero();  // S_e as a row over particles
        s[spring.i] = 1.0;
        s[spring.j] = -1.0;
        full += spring.stiffness * s * s.transpose();
      }
      const std::vector<int>& movable = problem.map.particle_of;
      const auto n = static_cast<Eigen::Index>(movable.size());
      Eigen::MatrixXd expected(n, n);
      for (Eigen::Index a = 0; a < n; ++a) {
        for (Eigen::Index b = 0; b < n; ++b) {
          expected(a, b) = full(movable[static_cast<std::size_t>(a)], movable[static_cast<std::size_t>(b)]);
        }
      }

      const cl::SparseMatrix a = cl::lab06::system_matrix(problem);
      REQUIRE(a.rows() == n);
      REQUIRE(a.cols() == n);
      const Eigen::MatrixXd dense(a);
      REQUIRE(cl::test::near(dense, expected, 1e-13 * expected.cwiseAbs().maxCoeff(), "unknown"));
      REQUIRE((dense - dense.transpose()).cwiseAbs().maxCoeff() == 0.0);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(dense);
      CAPTURE(eigen.eigenvalues().transpose());
      REQUIRE(eigen.eigenvalues().minCoeff() > 0.0);
    }
  }
  // Bad arguments: a non-finite or non-positive step, a hard or non-positive spring.
  Eigen::VectorXd inv_mass(2);
  inv_mass << 0.0, 1.0;
  cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, {{0, 1, 1.0, 10.0}}, 0.01);
  for (const double dt : {0.0, -0.01, std::nan(""), std::numeric_limits<double>::infinity()}) {
    cl::lab06::Problem bad = problem;
    bad.dt = dt;
    CAPTURE(dt);
    REQUIRE_THROWS_AS(cl::lab06::system_matrix(bad), std::invalid_argument);
  }
  for (const double k : {cl::kInfiniteStiffness, 0.0, -5.0, std::nan("")}) {
    cl::lab06::Problem bad = problem;
    bad.springs[0].stiffness = k;
    CAPTURE(k);
    REQUIRE_THROWS_AS(cl::lab06::system_matrix(bad), std::invalid_argument);
  }
}
