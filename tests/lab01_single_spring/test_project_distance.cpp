// Graded tests for lab01.1, project_distance. Properties and analytic cases.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "single_spring.h"
#include "tests/support/checks.h"

using cl::lab01::DistanceCorrection;
using cl::lab01::project_distance;
using Eigen::Vector3d;

namespace {

struct Case {
  Vector3d x_i, x_j;
  double inv_mass_i, inv_mass_j, rest_length;
};

// Random configurations: positions in a box of size `scale`, rest lengths from
// 0.1 to 3 times the current distance, inverse masses from 1e-2 to 1e2.
std::vector<Case> random_cases(unsigned seed, double scale, int count) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> log_mass(-2.0, 2.0);
  std::uniform_real_distribution<double> stretch(0.1, 3.0);
  std::vector<Case> cases;
  for (int c = 0; c < count; ++c) {
    Case item;
    item.x_i = scale * Vector3d(unit(rng), unit(rng), unit(rng));
    item.x_j = scale * Vector3d(unit(rng), unit(rng), unit(rng));
    item.inv_mass_i = std::pow(10.0, log_mass(rng));
    item.inv_mass_j = std::pow(10.0, log_mass(rng));
    item.rest_length = stretch(rng) * (item.x_i - item.x_j).norm();
    cases.push_back(item);
  }
  return cases;
}

double projected_length(const Case& item, const DistanceCorrection& correction) {
  return ((item.x_i + correction.dx_i) - (item.x_j + correction.dx_j)).norm();
}

void check_exact_length(double scale) {
  for (const Case& item : random_cases(7, scale, 200)) {
    CAPTURE(scale, item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const DistanceCorrection correction =
        project_distance(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length);
    REQUIRE(cl::test::near_rel(projected_length(item, correction), item.rest_length, 1e-12, "length after"));
  }
}

}  // namespace

TEST_CASE("one projection restores the rest length exactly", "[lab01][pts=2]") {
  check_exact_length(1.0);
  // Rest length 0 is valid input: the ends meet.
  const Vector3d a(0, 0, 0), b(1, 0, 0);
  const DistanceCorrection correction = project_distance(a, b, 1.0, 1.0, 0.0);
  CAPTURE(correction.dx_i.transpose(), correction.dx_j.transpose());
  REQUIRE(((a + correction.dx_i) - (b + correction.dx_j)).norm() == 0.0);
}

TEST_CASE("the correction splits by inverse mass along the constraint", "[lab01][pts=1]") {
  for (const Case& item : random_cases(11, 1.0, 100)) {
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const DistanceCorrection correction =
        project_distance(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const double share_i = correction.dx_i.norm() / (correction.dx_i.norm() + correction.dx_j.norm());
    REQUIRE(cl::test::near_rel(share_i, item.inv_mass_i / (item.inv_mass_i + item.inv_mass_j), 1e-12,
                                "share of end i, |dx_i| / (|dx_i| + |dx_j|)"));
    // Both corrections lie along d = x_i − x_j.
    const Vector3d d = item.x_i - item.x_j;
    REQUIRE(cl::test::near(d.cross(correction.dx_i).norm(), 0.0, 1e-12 * d.norm() * correction.dx_i.norm(),
                           "‖d × dx_i‖"));
    REQUIRE(cl::test::near(d.cross(correction.dx_j).norm(), 0.0, 1e-12 * d.norm() * correction.dx_j.norm(),
                           "‖d × dx_j‖"));
  }
}

TEST_CASE("linear and angular momentum are unchanged even with a pinned end", "[lab01][pts=1]") {
  // Σ m Δx = 0 and Σ m x × Δx = 0, multiplied through by w_i w_j so that a
  // pinned end (w = 0, infinite mass) needs no division:  w_j Δx_i + w_i Δx_j = 0.
  std::vector<Case> cases = random_cases(13, 1.0, 100);
  cases.push_back({Vector3d(0, 0, 0), Vector3d(2, 0, 0), 0.0, 1.0, 1.0});
  cases.push_back({Vector3d(0, 1, 0), Vector3d(0, 3, 1), 2.0, 0.0, 0.5});
  for (const Case& item : cases) {
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const DistanceCorrection correction =
        project_distance(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length);
    const double size = correction.dx_i.norm() + correction.dx_j.norm();
    REQUIRE(size > 0.0);
    const Vector3d momentum = item.inv_mass_j * correction.dx_i + item.inv_mass_i * correction.dx_j;
    const Vector3d angular =
        item.inv_mass_j * item.x_i.cross(correction.dx_i) + item.inv_mass_i * item.x_j.cross(correction.dx_j);
    const double scale = (item.inv_mass_i + item.inv_mass_j) * size;
    REQUIRE(cl::test::near(momentum.norm(), 0.0, 1e-13 * scale, "‖w_j dx_i + w_i dx_j‖"));
    REQUIRE(cl::test::near(angular.norm(), 0.0, 1e-13 * scale * (item.x_i.norm() + item.x_j.norm()),
                           "‖w_j x_i × dx_i + w_i x_j × dx_j‖"));
  }
}

TEST_CASE("one end pinned: the free end moves the whole way", "[lab01][pts=1]") {
  const Vector3d anchor(0.0, 0.0, 0.0);
  const Vector3d free_end(2.0, 0.0, 0.0);
  SECTION("pinned first") {
    const DistanceCorrection correction = project_distance(anchor, free_end, 0.0, 1.0 / 3.0, 1.0);
    REQUIRE(cl::test::near(correction.dx_i, Vector3d::Zero(), 0.0, "correction.dx_i"));
    REQUIRE(cl::test::near_rel(correction.dx_j.x(), -1.0, 1e-15, "dx_j.x"));
    REQUIRE(correction.dx_j.y() == 0.0);
    REQUIRE(correction.dx_j.z() == 0.0);
  }
  SECTION("pinned second") {
    const DistanceCorrection correction = project_distance(free_end, anchor, 5.0, 0.0, 0.5);
    REQUIRE(cl::test::near(correction.dx_j, Vector3d::Zero(), 0.0, "correction.dx_j"));
    REQUIRE(cl::test::near_rel(correction.dx_i.x(), -1.5, 1e-15, "dx_i.x"));
  }
}

TEST_CASE("both ends pinned: nothing moves", "[lab01][pts=1]") {
  const DistanceCorrection correction =
      project_distance(Vector3d(0, 0, 0), Vector3d(3, 4, 0), 0.0, 0.0, 1.0);
  REQUIRE(cl::test::near(correction.dx_i, Vector3d::Zero(), 0.0, "correction.dx_i"));
  REQUIRE(cl::test::near(correction.dx_j, Vector3d::Zero(), 0.0, "correction.dx_j"));
}

TEST_CASE("coincident particles give a zero correction and no NaN", "[lab01][pts=1]") {
  const Vector3d point(0.25, -1.0, 3.0);
  for (double rest_length : {0.0, 1.0}) {
    CAPTURE(rest_length);
    const DistanceCorrection correction = project_distance(point, point, 1.0, 2.0, rest_length);
    REQUIRE(cl::test::near(correction.dx_i, Vector3d::Zero(), 0.0, "correction.dx_i"));
    REQUIRE(cl::test::near(correction.dx_j, Vector3d::Zero(), 0.0, "correction.dx_j"));
  }
}

TEST_CASE("coordinates scaled by 1e6 and 1e-6 still project exactly", "[lab01][pts=1]") {
  for (double scale : {1e-6, 1e6}) check_exact_length(scale);
}

TEST_CASE("negative or non-finite inverse masses and rest lengths throw std::invalid_argument", "[lab01][pts=1]") {
  const Vector3d a(0, 0, 0), b(1, 0, 0);
  const double nan = std::nan(""), inf = HUGE_VAL;
  REQUIRE_THROWS_AS(project_distance(a, b, -1.0, 1.0, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(project_distance(a, b, 1.0, -1.0, 1.0), std::invalid_argument);
  REQUIRE_THROWS_AS(project_distance(a, b, 1.0, 1.0, -0.5), std::invalid_argument);
  for (const double bad : {nan, inf}) {
    CAPTURE(bad);
    REQUIRE_THROWS_AS(project_distance(a, b, bad, 1.0, 1.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance(a, b, 1.0, bad, 1.0), std::invalid_argument);
    REQUIRE_THROWS_AS(project_distance(a, b, 1.0, 1.0, bad), std::invalid_argument);
  }
}
