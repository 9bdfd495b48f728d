// Graded tests for lab10.1, project_unilateral_distance: a coarse constraint
// resists stretch only.
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "hpbd.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

namespace {

Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Vector3d d(normal(rng), normal(rng), normal(rng));
  return d.normalized();
}

}  // namespace

TEST_CASE("a compressed constraint is left untouched and a stretched one is projected exactly", "[lab10][pts=2]") {
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3d x_j(unit(rng), unit(rng), unit(rng));
    const Vector3d direction = random_unit(rng);
    const double rest = 0.01 + 2.0 * unit(rng);
    const double w_i = std::pow(10.0, 4.0 * unit(rng) - 2.0);
    const double w_j = trial % 5 == 0 ? 0.0 : std::pow(10.0, 4.0 * unit(rng) - 2.0);  // some pinned ends
    const double ratio = 0.05 + 2.0 * unit(rng);  // length / rest, both sides of 1
    const Vector3d x_i = x_j + ratio * rest * direction;
    CAPTURE(trial, x_i, x_j, w_i, w_j, rest, ratio);
    const cl::lab01::DistanceCorrection c = cl::lab10::project_unilateral_distance(x_i, x_j, w_i, w_j, rest);
    if ((x_i - x_j).norm() <= rest) {
      REQUIRE(c.dx_i == Vector3d::Zero());
      REQUIRE(c.dx_j == Vector3d::Zero());
      continue;
    }
    // Stretched: back to the rest length, along the constraint, lighter end moves more.
    const Vector3d y_i = x_i + c.dx_i, y_j = x_j + c.dx_j;
    REQUIRE(cl::test::near_rel((y_i - y_j).norm(), rest, 1e-12));
    REQUIRE(cl::test::near(c.dx_i.cross(direction).norm(), 0.0, 1e-12 * rest * ratio));
    REQUIRE(cl::test::near(c.dx_j.cross(direction).norm(), 0.0, 1e-12 * rest * ratio));
    // Mass-weighted split: m_i Δx_i + m_j Δx_j = 0, i.e. w_j Δx_i = −w_i Δx_j.
    REQUIRE(cl::test::near((w_j * c.dx_i + w_i * c.dx_j).norm(), 0.0, 1e-12 * (w_i + w_j) * rest * ratio));
    REQUIRE(c.dx_i.dot(direction) < 0.0);  // x_i moves towards x_j
  }
  // Exactly at the rest length: inactive.
  const cl::lab01::DistanceCorrection exact =
      cl::lab10::project_unilateral_distance(Vector3d(3, 4, 0), Vector3d::Zero(), 1.0, 1.0, 5.0);
  REQUIRE(exact.dx_i == Vector3d::Zero());
  REQUIRE(exact.dx_j == Vector3d::Zero());
}

TEST_CASE("unilateral projection of degenerate input is a no-op and bad arguments throw", "[lab10][pts=1]") {
  const Vector3d a(0, 0, 0), b(2, 0, 0);
  // Both ends pinned: stretched but nothing can move.
  const cl::lab01::DistanceCorrection pinned = cl::lab10::project_unilateral_distance(a, b, 0.0, 0.0, 1.0);
  REQUIRE(pinned.dx_i == Vector3d::Zero());
  REQUIRE(pinned.dx_j == Vector3d::Zero());
  // Coincident particles are never stretched (L >= 0), and zero rest length at zero distance is satisfied.
  const cl::lab01::DistanceCorrection coincident = cl::lab10::project_unilateral_distance(a, a, 1.0, 1.0, 0.0);
  REQUIRE(coincident.dx_i.allFinite());
  REQUIRE(coincident.dx_i == Vector3d::Zero());
  REQUIRE(coincident.dx_j == Vector3d::Zero());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {-1.0, nan, inf}) {
    CAPTURE(bad);
    // Bad arguments throw whether or not the constraint is stretched.
    REQUIRE_THROWS_AS(cl::lab10::project_unilateral_distance(a, b, bad, 1.0, 1.0), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab10::project_unilateral_distance(a, b, 1.0, bad, 3.0), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab10::project_unilateral_distance(a, b, 1.0, 1.0, bad), std::invalid_argument);
  }
}
