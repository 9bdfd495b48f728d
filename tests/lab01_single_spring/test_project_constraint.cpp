// Graded tests for lab01.2, project_constraint (the general gradient form).
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "single_spring.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

TEST_CASE("the general form reproduces the distance projection", "[lab01][pts=1]") {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Vector3d x_i(unit(rng), unit(rng), unit(rng));
    const Vector3d x_j(unit(rng), unit(rng), unit(rng));
    const double inv_mass_i = 1.0 + unit(rng), inv_mass_j = trial % 10 == 0 ? 0.0 : 1.5 + unit(rng);
    const double rest_length = 0.5 + std::abs(unit(rng));
    CAPTURE(x_i.transpose(), x_j.transpose(), inv_mass_i, inv_mass_j, rest_length);
    // C = ‖x_i − x_j‖ − L,  ∇_i C = n,  ∇_j C = −n.
    const Vector3d n = (x_i - x_j).normalized();
    Matrix3Xd gradients(3, 2);
    gradients << n, -n;
    const Matrix3Xd general = cl::lab01::project_constraint((x_i - x_j).norm() - rest_length, gradients,
                                                            VectorXd{{inv_mass_i, inv_mass_j}});
    const cl::lab01::DistanceCorrection special =
        cl::lab01::project_distance(x_i, x_j, inv_mass_i, inv_mass_j, rest_length);
    REQUIRE(general.cols() == 2);
    REQUIRE(cl::test::near((general.col(0) - special.dx_i).norm(), 0.0, 1e-14,
                           "‖column 0 − dx_i of project_distance‖"));
    REQUIRE(cl::test::near((general.col(1) - special.dx_j).norm(), 0.0, 1e-14,
                           "‖column 1 − dx_j of project_distance‖"));
  }
}

TEST_CASE("a linear constraint is satisfied by one projection", "[lab01][pts=1]") {
  // C(p) = Σ_k a_k·p_k − b has a constant gradient, so the linearised step is
  // exact: C(p + Δp) = 0. Three particles, one pinned.
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Matrix3Xd a(3, 3), p(3, 3);
    for (Eigen::Index k = 0; k < 3; ++k) {
      a.col(k) = Vector3d(unit(rng), unit(rng), unit(rng));
      p.col(k) = Vector3d(unit(rng), unit(rng), unit(rng));
    }
    const VectorXd inv_mass{{0.5 + unit(rng) * 0.4, 0.0, 2.0 + unit(rng)}};
    const double b = unit(rng);
    const double constraint = a.cwiseProduct(p).sum() - b;
    CAPTURE(a, p, inv_mass.transpose(), b);
    const Matrix3Xd correction = cl::lab01::project_constraint(constraint, a, inv_mass);
    REQUIRE(cl::test::near(correction.col(1), Vector3d::Zero(), 0.0, "correction.col(1)"));
    REQUIRE(cl::test::near(a.cwiseProduct(p + correction).sum() - b, 0.0, 1e-14, "C after the projection"));
  }
}

TEST_CASE("degenerate input gives zeros and invalid input throws in the general form", "[lab01][pts=1]") {
  Matrix3Xd gradients(3, 2);
  gradients << Vector3d(1, 0, 0), Vector3d(-1, 0, 0);
  SECTION("every particle pinned: zeros") {
    const Matrix3Xd correction = cl::lab01::project_constraint(0.5, gradients, VectorXd::Zero(2));
    REQUIRE(correction.cols() == 2);
    REQUIRE(cl::test::near(correction, Matrix3Xd::Zero(3, 2), 0.0, "particle"));
  }
  SECTION("zero gradient: zeros") {
    const Matrix3Xd correction = cl::lab01::project_constraint(0.5, Matrix3Xd::Zero(3, 2), VectorXd::Ones(2));
    REQUIRE(correction.cols() == 2);
    REQUIRE(cl::test::near(correction, Matrix3Xd::Zero(3, 2), 0.0, "particle"));
  }
  SECTION("shapes disagree, or a mass, C or a gradient is negative or non-finite: std::invalid_argument") {
    REQUIRE_THROWS_AS(cl::lab01::project_constraint(0.5, gradients, VectorXd::Ones(3)), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab01::project_constraint(0.5, gradients, VectorXd{{1.0, -1.0}}), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab01::project_constraint(0.5, gradients, VectorXd{{1.0, HUGE_VAL}}), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab01::project_constraint(std::nan(""), gradients, VectorXd::Ones(2)), std::invalid_argument);
    Matrix3Xd bad_gradients = gradients;
    bad_gradients(1, 1) = std::nan("");
    REQUIRE_THROWS_AS(cl::lab01::project_constraint(0.5, bad_gradients, VectorXd::Ones(2)), std::invalid_argument);
  }
}
