// Graded tests for lab13.4: the convergence test, on residuals written by hand.
#include <cmath>
#include <limits>
#include <string>
#include <stdexcept>

#include "tests/support/catch.h"

#include "constrained_newton.h"
#include "tests/support/checks.h"

using cl::test::answer;
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

// "convergence(r, L, tol).converged": the call as the failure's text shows it.
std::string call(const char* what, double length_scale, double tolerance) {
  return std::string("convergence(") + what + ", length_scale " + std::to_string(length_scale) + ", tolerance " +
         std::to_string(tolerance) + ").converged";
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
  CHECK(answer(call("force error 0.0625, constraint error 3e-3", 0.1, 1e-2), c.converged, false,
               "the force error 0.0625 is above the tolerance 1e-2"));
  CHECK(answer(call("force error 0.0625, constraint error 3e-3", 0.1, 0.0625),
               cl::lab13::convergence(r, 0.1, 0.0625).converged, true, "both errors are <= the tolerance 0.0625"));
  CHECK(answer(call("force error 0.0625, constraint error 3e-3", 0.1, 0.06),
               cl::lab13::convergence(r, 0.1, 0.06).converged, false, "the force error 0.0625 is above 0.06"));
  // The constraint error alone can hold it back.
  const cl::lab13::Residuals balanced = residuals_of(inertia, inertia, constraint);
  const cl::lab13::Convergence b = cl::lab13::convergence(balanced, 0.1, 1e-3);
  CHECK(near(b.force_error, 0.0, 0.0, "balanced forces"));
  CHECK(answer(call("force error 0, constraint error 3e-3", 0.1, 1e-3), b.converged, false,
               "the constraint error 3e-4 m / 0.1 m = 3e-3 is above the tolerance 1e-3"));
  CHECK(answer(call("force error 0, constraint error 3e-3", 0.1, 3e-3),
               cl::lab13::convergence(balanced, 0.1, 3e-3).converged, true, "both errors are <= 3e-3"));
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
  CHECK(answer(call("all residuals 0", 1.0, 1e-12), c.converged, true, "both errors are 0"));
  const cl::lab13::Residuals empty =
      residuals_of(Eigen::VectorXd(), Eigen::VectorXd(), Eigen::VectorXd::Constant(1, 2e-3));
  const cl::lab13::Convergence e = cl::lab13::convergence(empty, 0.5, 1e-2);
  CHECK(near(e.force_error, 0.0, 0.0, "no unknowns"));
  CHECK(near(e.constraint_error, 4e-3, 1e-18, "2e-3 m / 0.5 m"));
  CHECK(answer(call("no unknowns, constraint error 4e-3", 0.5, 1e-2), e.converged, true,
               "4e-3 is below the tolerance 1e-2"));
}

TEST_CASE("convergence never calls a NaN or infinite residual converged", "[lab13][pts=1]") {
  // A step whose iterate went non-finite (a huge dt, a bad mass) must not end
  // as "converged": the error is not a number, and NaN <= tol is false only if
  // the NaN reaches the comparison (a guard such as "imbalance > 0" lets it
  // through as 0). The NaN sits at the first and at a later entry.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Index at : {Eigen::Index(0), Eigen::Index(2)}) {
    for (const double bad : {nan, std::numeric_limits<double>::infinity()}) {
      CAPTURE(at, bad);
      Eigen::VectorXd inertia = Eigen::VectorXd::Constant(3, 1.0);
      Eigen::VectorXd pull = Eigen::VectorXd::Constant(3, 1.0);
      pull[at] = bad;
      const cl::lab13::Convergence f =
          cl::lab13::convergence(residuals_of(inertia, pull, Eigen::VectorXd::Zero(1)), 1.0, 1e-8);
      CHECK(answer(call("a force residual with a non-finite entry", 1.0, 1e-8), f.converged, false,
                   "a force imbalance that is not a number is not converged"));
      CHECK(answer("std::isfinite(force_error = " + std::to_string(f.force_error) + ")", std::isfinite(f.force_error),
                   false, "the force error of a non-finite residual is not finite"));
      Eigen::VectorXd phi = Eigen::VectorXd::Zero(3);
      phi[at] = bad;
      const cl::lab13::Convergence g = cl::lab13::convergence(residuals_of(inertia, inertia, phi), 1.0, 1e-8);
      CHECK(answer(call("a constraint residual with a non-finite entry", 1.0, 1e-8), g.converged, false,
                   "a constraint error that is not a number is not converged"));
    }
  }
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
