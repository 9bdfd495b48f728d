// Graded tests of lab11.1: the Chebyshev weights in closed form.
#include <cmath>
#include <stdexcept>

#include "tests/support/catch.h"

#include "acceleration.h"
#include "tests/support/checks.h"


TEST_CASE("the Chebyshev weights start at 1 and 2 over 2 - rho^2 and fall to 2 over 1 + sqrt(1 - rho^2)",
          "[lab11][pts=2]") {
  for (const double rho : {0.0, 0.1, 0.5, 0.9, 0.99, 0.9992}) {
    CAPTURE(rho);
    const double first = cl::lab11::chebyshev_weight(1, rho, 1.0);
    REQUIRE(first == 1.0);
    const double second = cl::lab11::chebyshev_weight(2, rho, first);
    REQUIRE(cl::test::near_rel(second, 2.0 / (2.0 - rho * rho), 1e-15));
    // The smaller fixed point of ω = 4/(4 − ρ²ω), approached from above after ω_2.
    const double limit = 2.0 / (1.0 + std::sqrt(1.0 - rho * rho));
    double omega = second;
    for (int j = 3; j <= 4000; ++j) {
      const double next = cl::lab11::chebyshev_weight(j, rho, omega);
      CAPTURE(j, omega, next);
      REQUIRE(cl::test::near_rel(next, 4.0 / (4.0 - rho * rho * omega), 1e-15));
      REQUIRE(next <= omega);  // decreasing from ω_2
      REQUIRE(next >= limit * (1.0 - 1e-15));
      omega = next;
    }
    REQUIRE(cl::test::near_rel(omega, limit, 1e-12));
    if (rho == 0.0) REQUIRE(omega == 1.0);
  }
  // previous_omega is not read for j = 1 and 2.
  REQUIRE(cl::lab11::chebyshev_weight(1, 0.5, 7.0) == 1.0);
  REQUIRE(cl::test::near_rel(cl::lab11::chebyshev_weight(2, 0.5, -3.0), 2.0 / 1.75, 1e-15));
  // Refused: j < 1, ρ outside [0, 1) or not finite, ω_(j−1) outside [1, 2).
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(0, 0.5, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(2, 1.0, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(3, 1.5, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(2, -0.1, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(1, std::nan(""), 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(3, 0.5, 2.0), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(3, 0.5, 0.5), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab11::chebyshev_weight(3, 0.5, std::nan("")), std::invalid_argument);
}
