// Hidden graded test for lab01.2 (run only by the Gradescope bundle, shown to
// the student after grades are published): the general projection does not
// depend on how the constraint is scaled.
#include <random>

#include "tests/support/catch.h"

#include "single_spring.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

TEST_CASE("scaling the constraint and its gradients by s leaves the general projection unchanged",
          "[lab01][pts=1][hidden]") {
  // C -> sC and grad C -> s grad C describe the same constraint surface:
  //   dp_k = -(sC) w_k (s grad_k C) / sum_j w_j |s grad_j C|^2  is independent of s.
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Index n = 2 + trial % 4;
    Matrix3Xd gradients(3, n);
    VectorXd inv_mass(n);
    for (Eigen::Index k = 0; k < n; ++k) {
      gradients.col(k) = Vector3d(unit(rng), unit(rng), unit(rng));
      inv_mass[k] = k == 0 && trial % 3 == 0 ? 0.0 : 1.0 + unit(rng) * 0.9;
    }
    const double constraint = unit(rng);
    const Matrix3Xd unscaled = cl::lab01::project_constraint(constraint, gradients, inv_mass);
    for (const double s : {-3.0, 1e-4, 1e4}) {
      CAPTURE(trial, s, constraint, gradients, inv_mass.transpose());
      const Matrix3Xd scaled = cl::lab01::project_constraint(s * constraint, s * gradients, inv_mass);
      REQUIRE(unscaled.norm() > 0.0);
      REQUIRE(cl::test::near(scaled, unscaled, 1e-12 * unscaled.norm(), "particle"));
    }
  }
}
