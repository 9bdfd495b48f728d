// Hidden graded tests of lab11.1 and lab11.2 (run only by the Gradescope
// bundle and the honesty checks): the weights against the Chebyshev
// polynomials, and the update's invariance under a translation.
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "acceleration.h"
#include "tests/support/checks.h"
#include "linear_splitting.h"


TEST_CASE("the weights equal 2 T_(j-1)(1/rho) over rho T_j(1/rho)", "[lab11][pts=1][hidden]") {
  // From the three-term recurrence T_(j+1)(z) = 2z T_j(z) − T_(j−1)(z) at z = 1/ρ (README.md).
  for (const double rho : {0.3, 0.8, 0.97}) {
    double omega = 1.0;
    for (int j = 1; j <= 40; ++j) {
      omega = cl::lab11::chebyshev_weight(j, rho, omega);
      if (j == 1) continue;
      const double z = 1.0 / rho;
      const double closed = 2.0 * lab11_test::chebyshev_t(j - 1, z) / (rho * lab11_test::chebyshev_t(j, z));
      CAPTURE(rho, j, omega, closed);
      REQUIRE(cl::test::near_rel(omega, closed, 1e-12));
    }
  }
}

TEST_CASE("the accelerated update commutes with a translation", "[lab11][pts=1][hidden]") {
  // The three coefficients ωγ, ω(1 − γ) and 1 − ω sum to 1: moving every
  // input by t moves the output by t.
  std::mt19937_64 rng(1101);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Matrix3Xd q_hat = Eigen::Matrix3Xd::Random(3, 9), q = Eigen::Matrix3Xd::Random(3, 9),
                           q_previous = Eigen::Matrix3Xd::Random(3, 9);
    const Eigen::Vector3d t(unit(rng) * 5, unit(rng) * 5, unit(rng) * 5);
    const double omega = 1.0 + 0.99 * (0.5 + 0.5 * unit(rng)), gamma = 0.2 + 0.5 * (1.0 + unit(rng));
    CAPTURE(trial, omega, gamma, t.transpose());
    const Eigen::Matrix3Xd moved = cl::lab11::chebyshev_update(q_hat.colwise() + t, q.colwise() + t,
                                                               q_previous.colwise() + t, omega, gamma);
    const Eigen::Matrix3Xd expected = cl::lab11::chebyshev_update(q_hat, q, q_previous, omega, gamma).colwise() + t;
    REQUIRE(cl::test::near(moved, expected, 1e-13));
  }
}
