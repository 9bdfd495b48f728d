// Graded tests for lab13.4: the convergence test, on residuals written by hand.
#include <cmath>
#include <stdexcept>

#include <catch2/catch.hpp>

#include "constrained_newton.h"
#include "tests/support/checks.h"

using cl::test::near;

namespace {

cl::lab13::Residuals residuals_of(Eigen::VectorXd inertia, Eigen::VectorXd constraint_force,
                                  Eigen::VectorXd constraint) {
  cl::lab13::Residuals r;
  r.force = inertia - constraint_force;
  r.inertia = std::move(inertia);
  r.constraint_force = std::move(constraint_force);
  r.constraint = std::move(constraint);
  return r;
}

}  // namespace

TEST_CASE("convergence measures the force imbalance and the constraint error", "[lab13][pts=2]") {
  Eigen::VectorXd inertia(6), force(6), constraint(2);
  inertia << 2.0, -4.0, 0.5, 1.0, 0.0, -1.0;
  force << 2.0, -4.0, 0.5, 1.0, 0.0, -1.25;  // largest |Jᵀλ| is 4 N; imbalance 0.25 N at entry 5
  constraint << 1e-4, -3e-4;
  const cl::lab13::Residuals r = residuals_of(inertia, force, constraint);
  const cl::lab13::Convergence c = cl::lab13::convergence(r, 0.1, 1e-2);
  CHECK(near(c.force_error, 0.25 / 4.0, 1e-15, "force error = 0.25 N / 4 N"));
  CHECK(near(c.constraint_error, 3e-4 / 0.1, 1e-15, "constraint error = 3e-4 m / 0.1 m"));
  CHECK_FALSE(c.converged);  // 0.0625 > 1e-2
  CHECK(cl::lab13::convergence(r, 0.1, 0.0625).converged);
  CHECK_FALSE(cl::lab13::convergence(r, 0.1, 0.06).converged);
  // The constraint error alone can hold it back.
  const cl::lab13::Residuals balanced = residuals_of(inertia, inertia, constraint);
  const cl::lab13::Convergence b = cl::lab13::convergence(balanced, 0.1, 1e-3);
  CHECK(near(b.force_error, 0.0, 0.0, "balanced forces"));
  CHECK_FALSE(b.converged);  // 3e-3 > 1e-3
  CHECK(cl::lab13::convergence(balanced, 0.1, 3e-3).converged);
  // The larger of the two forces is the scale: here the inertia (8 N).
  Eigen::VectorXd heavy = inertia;
  heavy[1] = -8.0;
  const cl::lab13::Convergence h = cl::lab13::convergence(residuals_of(heavy, force, constraint), 1.0, 1.0);
  CHECK(near(h.force_error, 4.0 / 8.0, 1e-15, "force error = 4 N / 8 N"));
  // … or the constraint force (10 N), when it is the larger.
  Eigen::VectorXd pulled = force;
  pulled[2] = 10.0;  // imbalance 9.5 N at entry 2
  const cl::lab13::Convergence f = cl::lab13::convergence(residuals_of(inertia, pulled, constraint), 1.0, 1.0);
  CHECK(near(f.force_error, 9.5 / 10.0, 1e-15, "force error = 9.5 N / 10 N (the scale is the larger force, J^T lambda)"));
}

TEST_CASE("convergence is zero at rest and with nothing to balance", "[lab13][pts=1]") {
  const cl::lab13::Residuals zero =
      residuals_of(Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(0));
  const cl::lab13::Convergence c = cl::lab13::convergence(zero, 1.0, 1e-12);
  CHECK(near(c.force_error, 0.0, 0.0, "no force at all"));
  CHECK(near(c.constraint_error, 0.0, 0.0, "no springs"));
  CHECK(c.converged);
  const cl::lab13::Residuals empty =
      residuals_of(Eigen::VectorXd(), Eigen::VectorXd(), Eigen::VectorXd::Constant(1, 2e-3));
  const cl::lab13::Convergence e = cl::lab13::convergence(empty, 0.5, 1e-2);
  CHECK(near(e.force_error, 0.0, 0.0, "no unknowns"));
  CHECK(near(e.constraint_error, 4e-3, 1e-18, "2e-3 m / 0.5 m"));
  CHECK(e.converged);
}

TEST_CASE("convergence refuses a bad length scale or tolerance", "[lab13][pts=1]") {
  const cl::lab13::Residuals r =
      residuals_of(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(1));
  CHECK_THROWS_AS(cl::lab13::convergence(r, 0.0, 1e-6), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::convergence(r, std::nan(""), 1e-6), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::convergence(r, 1.0, -1e-6), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::convergence(r, 1.0, INFINITY), std::invalid_argument);
  cl::lab13::Residuals odd = r;
  odd.inertia.resize(2);
  CHECK_THROWS_AS(cl::lab13::convergence(odd, 1.0, 1e-6), std::invalid_argument);
}
