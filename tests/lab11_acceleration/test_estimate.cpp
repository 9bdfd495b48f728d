// Graded tests of lab11.3: the spectral radius from a plain run's update lengths.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "tests/support/catch.h"

#include "acceleration.h"
#include "tests/support/checks.h"
#include "linear_splitting.h"


TEST_CASE("the spectral radius is estimated from the last half of the update lengths", "[lab11][pts=2]") {
  // An exactly geometric run: the rate itself.
  for (const double rho : {0.2, 0.9, 0.999}) {
    for (const int n : {2, 3, 10, 41}) {
      std::vector<double> norms;
      for (int k = 0; k < n; ++k) norms.push_back(3.0 * std::pow(rho, k));
      CAPTURE(rho, n);
      REQUIRE(cl::test::near_rel(cl::lab11::estimate_spectral_radius(norms), rho, 1e-12));
    }
  }
  // The window is the last ⌊n/2⌋ ratios: whatever came before it is ignored.
  {
    const double rho = 0.7;
    const std::vector<double> norms{5.0, 0.1, 1.0, rho, rho * rho, std::pow(rho, 3), std::pow(rho, 4),
                                    std::pow(rho, 5)};
    REQUIRE(cl::test::near_rel(cl::lab11::estimate_spectral_radius(norms), rho, 1e-12));
  }
  // A fast mode that has died out by the second half.
  {
    std::vector<double> norms;
    for (int k = 0; k < 60; ++k) norms.push_back(std::pow(0.95, k) + 5.0 * std::pow(0.3, k));
    REQUIRE(cl::test::near_rel(cl::lab11::estimate_spectral_radius(norms), 0.95, 1e-9));
  }
  // A real run: Jacobi on tridiag(−1, 2, −1), ρ = cos(π/(n+1)), to 1e-3.
  for (const Eigen::Index n : {5, 10}) {
    const Eigen::Matrix3Xd b = Eigen::Matrix3Xd::Random(3, n);
    Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Random(3, n);
    std::vector<double> norms;
    for (int k = 0; k < 200; ++k) {
      const Eigen::Matrix3Xd next = lab11_test::jacobi(x, b);
      norms.push_back((next - x).norm());
      x = next;
    }
    CAPTURE(n);
    REQUIRE(cl::test::near(cl::lab11::estimate_spectral_radius(norms), lab11_test::splitting_rho(n), 1e-3));
  }
  // A run that reached exact convergence: nothing to accelerate.
  REQUIRE(cl::lab11::estimate_spectral_radius({1.0, 0.5, 0.0, 0.0}) == 0.0);
  REQUIRE(cl::lab11::estimate_spectral_radius({1.0, 0.0, 0.0, 0.5}) == 0.0);
  // A growing run is measured as it is (the caller refuses ρ >= 1).
  REQUIRE(cl::test::near_rel(cl::lab11::estimate_spectral_radius({1.0, 2.0, 4.0, 8.0}), 2.0, 1e-12));
  // Refused: fewer than two lengths, a negative or non-finite one.
  REQUIRE_THROWS_AS(cl::lab11::estimate_spectral_radius({}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::estimate_spectral_radius({1.0}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::estimate_spectral_radius({1.0, -0.5, 0.25}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::estimate_spectral_radius({1.0, std::nan(""), 0.25}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::estimate_spectral_radius({std::numeric_limits<double>::infinity(), 1.0}),
                    std::invalid_argument);
}
