// Graded tests for lab13.5 and lab13.6: the merit's weights and value in
// closed form, and the safeguard's rule.
#include <cmath>
#include <cstdio>
#include <string>
#include <limits>
#include <stdexcept>

#include "tests/support/catch.h"

#include "constrained_newton.h"
#include "tests/support/checks.h"

using cl::test::near;

TEST_CASE("merit weights are one over compliance plus dt squared times the inverse masses", "[lab13][pts=2]") {
  Eigen::VectorXd inv_mass(4);
  inv_mass << 0.0, 2.0, 0.5, 0.0;  // particles 0 and 3 pinned
  const std::vector<cl::Spring> springs{{0, 1, 1.0, 100.0}, {1, 2, 1.0, std::numeric_limits<double>::infinity()},
                                        {2, 3, 1.0, 1e6}, {0, 3, 1.0, std::numeric_limits<double>::infinity()}};
  Eigen::VectorXd compliance(4);
  compliance << 0.01, 0.0, 1e-6, 0.0;
  const double dt = 0.1;
  const Eigen::VectorXd w = cl::lab13::merit_weights(springs, inv_mass, compliance, dt);
  REQUIRE(w.size() == 4);
  CHECK(near(w[0], 1.0 / (0.01 + 0.01 * 2.0), 1e-12, "spring 0: 1/(c + dt^2 w_1)"));
  CHECK(near(w[1], 1.0 / (0.01 * 2.5), 1e-12, "spring 1, hard: 1/(dt^2 (w_1 + w_2))"));
  CHECK(near(w[2], 1.0 / (1e-6 + 0.01 * 0.5), 1e-10, "spring 2"));
  CHECK(near(w[3], 0.0, 0.0, "spring 3, hard between two pins: 0"));
  // Every spring hard: lab 07's empty compliance.
  const Eigen::VectorXd hard = cl::lab13::merit_weights(springs, inv_mass, Eigen::VectorXd(), dt);
  REQUIRE(hard.size() == 4);
  CHECK(near(hard[0], 1.0 / (0.01 * 2.0), 1e-12, "spring 0 with C = 0"));
  CHECK_THROWS_AS(cl::lab13::merit_weights(springs, inv_mass, compliance.head(3), dt), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::merit_weights(springs, inv_mass, compliance, 0.0), std::invalid_argument);
}

TEST_CASE("merit is the weighted squared residual in joules", "[lab13][pts=2]") {
  Eigen::VectorXd inv_mass(3);
  inv_mass << 0.0, 2.0, 0.25;
  const cl::MovableMap map = cl::make_movable_map(inv_mass);  // unknowns: particles 1, 2
  cl::lab13::Residuals r;
  r.force.resize(6);
  r.force << 1.0, -2.0, 0.0, 4.0, 0.0, 2.0;  // N
  r.inertia = r.force;
  r.constraint_force = Eigen::VectorXd::Zero(6);
  r.constraint.resize(2);
  r.constraint << 0.01, -0.02;  // m
  Eigen::VectorXd weights(2);
  weights << 100.0, 50.0;  // N/m
  const double dt = 0.1;
  // ½ dt² (2 (1 + 4) + 0.25 (16 + 4)) + ½ (100 · 1e-4 + 50 · 4e-4)
  const double expected = 0.5 * 0.01 * (2.0 * 5.0 + 0.25 * 20.0) + 0.5 * (0.01 + 0.02);
  CHECK(near(cl::lab13::merit(r, inv_mass, map, weights, dt), expected, 1e-15, "psi (J)"));
  cl::lab13::Residuals zero = r;
  zero.force.setZero();
  zero.constraint.setZero();
  CHECK(near(cl::lab13::merit(zero, inv_mass, map, weights, dt), 0.0, 0.0, "psi at the step"));
  CHECK_THROWS_AS(cl::lab13::merit(r, inv_mass, map, weights.head(1), dt), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::merit(r, inv_mass, map, weights, -0.1), std::invalid_argument);
}

TEST_CASE("sufficient decrease is Armijo's rule on the merit", "[lab13][pts=2]") {
  using cl::lab13::sufficient_decrease;
  const double psi = 2.0;
  for (const double alpha : {1.0, 0.5, 0.125, 1.0 / 4096.0}) {
    CAPTURE(alpha);
    const double bound = (1.0 - 2.0 * cl::lab13::kArmijo * alpha) * psi;
    const std::string rule = "the bound (1 - 2 sigma alpha) psi(0) = " + std::to_string(bound);
    auto call = [&](double after) {
      char text[160];
      std::snprintf(text, sizeof text, "sufficient_decrease(%.17g, %.17g, %.17g)", psi, after, alpha);
      return std::string(text);
    };
    CHECK(cl::test::answer(call(bound), sufficient_decrease(psi, bound, alpha), true, "psi(alpha) equals " + rule));
    CHECK(cl::test::answer(call(0.5 * bound), sufficient_decrease(psi, 0.5 * bound, alpha), true,
                           "psi(alpha) is below " + rule));
    const double above = std::nextafter(bound, 10.0);
    CHECK(cl::test::answer(call(above), sufficient_decrease(psi, above, alpha), false,
                           "psi(alpha) is one ulp above " + rule));
    CHECK(cl::test::answer(call(psi), sufficient_decrease(psi, psi, alpha), false, "psi did not fall at all"));
    CHECK(cl::test::answer(call(std::nan("")), sufficient_decrease(psi, std::nan(""), alpha), false,
                           "a NaN merit is never a decrease"));
    CHECK(cl::test::answer(call(INFINITY), sufficient_decrease(psi, INFINITY, alpha), false,
                           "an infinite merit is never a decrease"));
  }
  CHECK_THROWS_AS(sufficient_decrease(psi, 1.0, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(sufficient_decrease(psi, 1.0, 1.5), std::invalid_argument);
  CHECK_THROWS_AS(sufficient_decrease(-1.0, 0.0, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(sufficient_decrease(std::nan(""), 0.0, 1.0), std::invalid_argument);
}
