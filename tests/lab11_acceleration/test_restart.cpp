// Graded tests of lab11.4: the restart rule.
#include <cmath>
#include <limits>
#include <stdexcept>

#include <catch2/catch.hpp>

#include "acceleration.h"

TEST_CASE("a restart is needed exactly when the objective rises past the slack or is not finite", "[lab11][pts=1]") {
  using cl::lab11::restart_needed;
  const double inf = std::numeric_limits<double>::infinity();
  REQUIRE_FALSE(restart_needed(10.0, 9.0, 0.0));
  REQUIRE_FALSE(restart_needed(10.0, 10.0, 0.0));
  REQUIRE(restart_needed(10.0, 10.5, 0.0));
  REQUIRE(restart_needed(10.0, 10.0 + 1e-12, 0.0));
  // The slack is relative to |objective_before|.
  REQUIRE_FALSE(restart_needed(10.0, 10.0 + 9e-12, 1e-12));
  REQUIRE(restart_needed(10.0, 10.0 + 2e-11, 1e-12));
  REQUIRE_FALSE(restart_needed(-10.0, -10.0 + 9e-12, 1e-12));
  REQUIRE(restart_needed(-10.0, -9.0, 1e-12));
  REQUIRE_FALSE(restart_needed(0.0, 0.0, 1e-12));
  REQUIRE(restart_needed(0.0, 1e-300, 1e-12));
  // Not finite: always a restart, never a silent NaN.
  REQUIRE(restart_needed(10.0, std::nan(""), 1e-12));
  REQUIRE(restart_needed(10.0, inf, 1e-12));
  REQUIRE(restart_needed(10.0, -inf, 1e-12));
  // Refused.
  REQUIRE_THROWS_AS(restart_needed(std::nan(""), 1.0, 0.0), std::invalid_argument);
  REQUIRE_THROWS_AS(restart_needed(inf, 1.0, 0.0), std::invalid_argument);
  REQUIRE_THROWS_AS(restart_needed(1.0, 1.0, -1e-12), std::invalid_argument);
  REQUIRE_THROWS_AS(restart_needed(1.0, 1.0, std::nan("")), std::invalid_argument);
}
