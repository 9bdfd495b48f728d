// Graded tests of lab11.2: the accelerated update, and of lab11.1 and lab11.2
// together: on a linear iteration the error follows the Chebyshev bound.
#include <cmath>
#include <random>
#include <stdexcept>

#include "tests/support/catch.h"

#include "acceleration.h"
#include "tests/support/checks.h"
#include "linear_splitting.h"

using Eigen::Matrix3Xd;

TEST_CASE("the accelerated update is omega (gamma (q_hat - q) + q - q_previous) + q_previous", "[lab11][pts=2]") {
  std::mt19937_64 rng(1102);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Index n = 1 + trial;
    const Matrix3Xd q_hat = Matrix3Xd::Random(3, n), q = Matrix3Xd::Random(3, n),
                    q_previous = Matrix3Xd::Random(3, n);
    const double omega = 1.0 + 0.999 * unit(rng), gamma = 0.05 + 1.9 * unit(rng);
    CAPTURE(trial, omega, gamma);
    const Matrix3Xd expected = omega * (gamma * (q_hat - q) + q - q_previous) + q_previous;
    REQUIRE(cl::test::near(cl::lab11::chebyshev_update(q_hat, q, q_previous, omega, gamma), expected, 1e-14));
    // ω = γ = 1: the plain iterate, bit for bit.
    REQUIRE(cl::test::near(cl::lab11::chebyshev_update(q_hat, q, q_previous, 1.0, 1.0), q_hat, 0.0));
    // ω = 1: the under-relaxed plain iterate q + γ (q_hat − q).
    REQUIRE(cl::test::near(cl::lab11::chebyshev_update(q_hat, q, q_previous, 1.0, gamma),
                                 Matrix3Xd(q + gamma * (q_hat - q)), 1e-14));
  }
  const Matrix3Xd three = Matrix3Xd::Random(3, 3), four = Matrix3Xd::Random(3, 4);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, four, three, 1.2, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, four, 1.2, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, 2.0, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, 0.9, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, std::nan(""), 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, 1.2, 0.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, 1.2, 2.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_update(three, three, three, 1.2, std::nan("")), std::invalid_argument);
}

TEST_CASE("on a linear iteration with spectral radius rho the accelerated error is within the Chebyshev bound",
          "[lab11][pts=2]") {
  // Jacobi on tridiag(−1, 2, −1): B symmetric with spectrum in [−ρ, ρ]. With the
  // weights of ρ and γ = 1 the error after k iterations is P_k(B) e_0,
  // P_k(t) = T_k(t/ρ)/T_k(1/ρ), so ‖e_k‖ <= ‖e_0‖ / T_k(1/ρ), with equality
  // when e_0 is the mode of eigenvalue ρ (README.md, "The weights").
  for (const Eigen::Index n : {6, 20}) {
    const double rho = lab11_test::splitting_rho(n);
    const Matrix3Xd solution = Matrix3Xd::Random(3, n);
    const Matrix3Xd b = lab11_test::times_a(solution);
    for (const bool slowest_mode : {true, false}) {
      const Matrix3Xd start = slowest_mode ? Matrix3Xd(solution + lab11_test::mode(n, 1)) : Matrix3Xd::Random(3, n);
      const double e0 = (start - solution).norm();
      Matrix3Xd x = start, previous = start, plain = start;
      double omega = 1.0;
      for (int k = 1; k <= 60; ++k) {
        omega = cl::lab11::chebyshev_weight(k, rho, omega);
        const Matrix3Xd next = cl::lab11::chebyshev_update(lab11_test::jacobi(x, b), x, previous, omega, 1.0);
        previous = x;
        x = next;
        plain = lab11_test::jacobi(plain, b);
        const double bound = e0 / lab11_test::chebyshev_t(k, 1.0 / rho);
        const double error = (x - solution).norm();
        CAPTURE(n, slowest_mode, k, omega, error, bound, e0);
        REQUIRE(error <= bound * (1.0 + 1e-9) + 1e-13 * e0);
        if (slowest_mode) REQUIRE(std::abs(error - bound) <= 1e-9 * bound + 1e-13 * e0);
      }
      // Plain Jacobi: the slowest mode shrinks by ρ per iteration only.
      if (slowest_mode) REQUIRE((plain - solution).norm() > 10.0 * (x - solution).norm());
    }
  }
}
