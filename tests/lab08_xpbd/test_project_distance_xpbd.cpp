// Graded tests for lab08.1, project_distance_xpbd: lab 01's projection at
// zero compliance, the compliant constraint solved in one projection, the
// degenerate and invalid cases.
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "single_spring.h"
#include "xpbd.h"
#include "tests/support/checks.h"

using cl::lab08::project_distance_xpbd;
using cl::lab08::XpbdCorrection;
using Eigen::Vector3d;

namespace {

struct Case {
  Vector3d x_i, x_j;
  double inv_mass_i = 1.0, inv_mass_j = 1.0, rest_length = 1.0;
  double alpha_tilde = 0.0, lambda = 0.0;
};

// Random configurations: positions in a unit box, rest lengths from 0.1 to 3
// times the current distance, inverse masses from 1e-2 to 1e2 (one in five
// cases pins one end), α̃ from 1e-4 to 1e4 1/kg, and λ with |α̃λ| <= L/2, so
// that the length the projection aims at, L − α̃λ', stays positive (the new
// length is a weighted mean of the old one and L − α̃λ).
std::vector<Case> random_cases(unsigned seed, int count, bool compliant) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> stretch(0.1, 3.0);
  std::vector<Case> cases;
  for (int c = 0; c < count; ++c) {
    Case item;
    item.x_i = Vector3d(unit(rng), unit(rng), unit(rng));
    item.x_j = Vector3d(unit(rng), unit(rng), unit(rng));
    item.inv_mass_i = c % 5 == 1 ? 0.0 : std::pow(10.0, 2.0 * unit(rng));
    item.inv_mass_j = std::pow(10.0, 2.0 * unit(rng));
    item.rest_length = stretch(rng) * (item.x_i - item.x_j).norm();
    if (compliant) {
      item.alpha_tilde = std::pow(10.0, 4.0 * unit(rng));
      item.lambda = 0.5 * unit(rng) * item.rest_length / item.alpha_tilde;
    }
    cases.push_back(item);
  }
  return cases;
}

XpbdCorrection project(const Case& item) {
  return project_distance_xpbd(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length,
                               item.alpha_tilde, item.lambda);
}

}  // namespace

TEST_CASE("with zero compliance and zero multiplier the XPBD projection is lab 01's", "[lab08][pts=1]") {
  // α̃ = 0, λ = 0: Δλ = −C/(w_i + w_j) and Δx_i = w_i Δλ n is lab 01's −w_i C n/(w_i + w_j).
  for (const Case& item : random_cases(3, 200, false)) {
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const XpbdCorrection xpbd = project(item);
    const cl::lab01::DistanceCorrection pbd =
        cl::lab01::project_distance(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const double scale = 1e-13 * (item.x_i.norm() + item.x_j.norm() + item.rest_length);
    CAPTURE(xpbd.dx_i.transpose(), pbd.dx_i.transpose(), xpbd.dx_j.transpose(), pbd.dx_j.transpose());
    REQUIRE(cl::test::near(xpbd.dx_i, pbd.dx_i, scale));
    REQUIRE(cl::test::near(xpbd.dx_j, pbd.dx_j, scale));
    const double constraint = (item.x_i - item.x_j).norm() - item.rest_length;
    REQUIRE(cl::test::near_rel(xpbd.dlambda, -constraint / (item.inv_mass_i + item.inv_mass_j), 1e-12));
  }
}

TEST_CASE("one XPBD projection solves C plus alpha_tilde times lambda equals zero", "[lab08][pts=2]") {
  // The move is along d, so the new length is ‖d‖ + (w_i + w_j)Δλ and
  //   C' + α̃(λ + Δλ) = C + α̃λ + (w_i + w_j + α̃)Δλ = 0.
  // The corrections are w_i Δλ n and −w_j Δλ n: the centre of mass stays put.
  // A second projection with the updated λ has nothing left to do.
  for (const Case& item : random_cases(5, 300, true)) {
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length,
            item.alpha_tilde, item.lambda);
    const XpbdCorrection correction = project(item);
    CAPTURE(correction.dx_i.transpose(), correction.dx_j.transpose(), correction.dlambda);
    Case after = item;
    after.x_i += correction.dx_i;
    after.x_j += correction.dx_j;
    after.lambda += correction.dlambda;
    const double residual = (after.x_i - after.x_j).norm() - item.rest_length + item.alpha_tilde * after.lambda;
    const double scale = item.x_i.norm() + item.x_j.norm() + item.rest_length +
                         item.alpha_tilde * (std::abs(item.lambda) + std::abs(correction.dlambda));
    REQUIRE(cl::test::near(residual, 0.0, 1e-13 * scale));

    const Vector3d n = (item.x_i - item.x_j).normalized();
    REQUIRE(cl::test::near((correction.dx_i - item.inv_mass_i * correction.dlambda * n).norm(), 0.0, 1e-14 * (1.0 + correction.dx_i.norm())));
    REQUIRE(cl::test::near((correction.dx_j + item.inv_mass_j * correction.dlambda * n).norm(), 0.0, 1e-14 * (1.0 + correction.dx_j.norm())));

    const XpbdCorrection again = project(after);
    CAPTURE(again.dlambda);
    REQUIRE(cl::test::near(again.dlambda * (item.inv_mass_i + item.inv_mass_j + item.alpha_tilde), 0.0, 1e-13 * scale));
  }
}

TEST_CASE("degenerate XPBD projections are no-ops and invalid input throws", "[lab08][pts=1]") {
  const Vector3d a(0.1, 0.2, 0.3), b(1.0, -0.5, 0.25);
  SECTION("coincident particles: no direction, all zero") {
    const XpbdCorrection correction = project_distance_xpbd(a, a, 1.0, 2.0, 0.5, 3.0, 0.7);
    CAPTURE(correction.dx_i.transpose(), correction.dx_j.transpose(), correction.dlambda);
    REQUIRE(correction.dx_i == Vector3d::Zero());
    REQUIRE(correction.dx_j == Vector3d::Zero());
    REQUIRE(correction.dlambda == 0.0);
  }
  SECTION("both ends pinned and hard: all zero") {
    const XpbdCorrection correction = project_distance_xpbd(a, b, 0.0, 0.0, 0.5, 0.0, 0.7);
    CAPTURE(correction.dx_i.transpose(), correction.dx_j.transpose(), correction.dlambda);
    REQUIRE(correction.dx_i == Vector3d::Zero());
    REQUIRE(correction.dx_j == Vector3d::Zero());
    REQUIRE(correction.dlambda == 0.0);
  }
  SECTION("both ends pinned and compliant: nothing moves, the multiplier takes the spring's value") {
    const double alpha_tilde = 4.0, lambda = 0.25;
    const double constraint = (a - b).norm() - 0.5;
    const XpbdCorrection correction = project_distance_xpbd(a, b, 0.0, 0.0, 0.5, alpha_tilde, lambda);
    CAPTURE(correction.dx_i.transpose(), correction.dx_j.transpose(), correction.dlambda);
    REQUIRE(correction.dx_i == Vector3d::Zero());
    REQUIRE(correction.dx_j == Vector3d::Zero());
    REQUIRE(cl::test::near_rel(correction.dlambda, (-constraint - alpha_tilde * lambda) / alpha_tilde, 1e-14));
  }
  SECTION("invalid arguments throw std::invalid_argument") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, -1.0, 1.0, 0.5, 1.0, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, nan, 0.5, 1.0, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, 1.0, -0.5, 1.0, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, 1.0, 0.5, -1.0, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, 1.0, 0.5, inf, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, 1.0, 0.5, nan, 0.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance_xpbd(a, b, 1.0, 1.0, 0.5, 1.0, nan), std::invalid_argument);
    REQUIRE_NOTHROW(project_distance_xpbd(a, b, 1.0, 1.0, 0.0, 0.0, 0.0));
  }
}
