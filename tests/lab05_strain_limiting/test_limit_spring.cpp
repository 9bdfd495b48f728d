// Graded tests for lab05.1, limit_spring: the band, the no-op inside it,
// momentum, pinned ends, and the two formulas of the seed notes.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tests/support/catch.h"

#include "strain_limiting.h"
#include "tests/support/checks.h"

using cl::lab01::DistanceCorrection;
using cl::lab05::limit_spring;
using Eigen::Vector3d;

namespace {

struct SpringCase {
  Vector3d x_i, x_j;
  double inv_mass_i, inv_mass_j, rest_length, sigma_min, sigma_max;
};

// Random springs in a box of size `scale`: rest lengths from 0.2 to 5 times the
// current distance (so σ from 0.2 to 5), inverse masses from 1e-2 to 1e2, and
// one of four bands (the last one is an equality: lab 01's projection).
std::vector<SpringCase> random_spring_cases(unsigned seed, double scale, int count) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> log_mass(-2.0, 2.0);
  std::uniform_real_distribution<double> log_stretch(std::log(0.2), std::log(5.0));
  const double bands[4][2] = {{0.9, 1.1}, {0.5, 2.0}, {0.99, 1.0}, {1.0, 1.0}};
  std::vector<SpringCase> cases;
  for (int c = 0; c < count; ++c) {
    SpringCase item;
    item.x_i = scale * Vector3d(unit(rng), unit(rng), unit(rng));
    item.x_j = scale * Vector3d(unit(rng), unit(rng), unit(rng));
    item.inv_mass_i = std::pow(10.0, log_mass(rng));
    item.inv_mass_j = std::pow(10.0, log_mass(rng));
    item.rest_length = (item.x_i - item.x_j).norm() / std::exp(log_stretch(rng));
    item.sigma_min = bands[c % 4][0];
    item.sigma_max = bands[c % 4][1];
    cases.push_back(item);
  }
  return cases;
}

DistanceCorrection limit_spring_case(const SpringCase& item) {
  return limit_spring(item.x_i, item.x_j, item.inv_mass_i, item.inv_mass_j, item.rest_length, item.sigma_min,
                      item.sigma_max);
}

double sigma_of(const SpringCase& item) { return (item.x_i - item.x_j).norm() / item.rest_length; }

double length_after(const SpringCase& item, const DistanceCorrection& correction) {
  return ((item.x_i + correction.dx_i) - (item.x_j + correction.dx_j)).norm();
}

}  // namespace

TEST_CASE("one spring limit brings the length to the nearer end of the band", "[lab05][pts=1]") {
  int outside = 0;
  for (const double scale : {1e-3, 1.0, 1e3}) {
    for (const SpringCase& item : random_spring_cases(7, scale, 300)) {
      const double sigma = sigma_of(item);
      const double target = std::clamp(sigma, item.sigma_min, item.sigma_max) * item.rest_length;
      CAPTURE(scale, item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length,
              item.sigma_min, item.sigma_max, sigma);
      const double length = length_after(item, limit_spring_case(item));
      REQUIRE(cl::test::near_rel(length, target, 1e-12));
      REQUIRE(length >= item.sigma_min * item.rest_length * (1.0 - 1e-12));
      REQUIRE(length <= item.sigma_max * item.rest_length * (1.0 + 1e-12));
      outside += sigma < item.sigma_min || sigma > item.sigma_max;
    }
  }
  REQUIRE(outside > 300);  // most cases had something to do
}

TEST_CASE("a spring inside the band is untouched and a second limit changes nothing", "[lab05][pts=1]") {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> inside(0.0, 1.0);
  int limited = 0;
  for (SpringCase item : random_spring_cases(11, 1.0, 300)) {
    // Moved into the band (its ends included): exactly zero corrections.
    SpringCase in_band = item;
    const double sigma = item.sigma_min + inside(rng) * (item.sigma_max - item.sigma_min);
    in_band.rest_length = (item.x_i - item.x_j).norm() / sigma;
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, in_band.rest_length,
            item.sigma_min, item.sigma_max, sigma_of(in_band));
    if (sigma_of(in_band) >= item.sigma_min && sigma_of(in_band) <= item.sigma_max) {
      const DistanceCorrection none = limit_spring_case(in_band);
      REQUIRE(cl::test::near(none.dx_i, Vector3d::Zero(), 0.0, "none.dx_i"));
      REQUIRE(cl::test::near(none.dx_j, Vector3d::Zero(), 0.0, "none.dx_j"));
    }
    // Idempotent: limiting the limited spring again moves nothing beyond round-off.
    CAPTURE(item.rest_length, sigma_of(item));
    const DistanceCorrection first = limit_spring_case(item);
    limited += first.dx_i.norm() + first.dx_j.norm() > 0.0;
    SpringCase again = item;
    again.x_i += first.dx_i;
    again.x_j += first.dx_j;
    const DistanceCorrection second = limit_spring_case(again);
    REQUIRE(cl::test::near(second.dx_i.norm() + second.dx_j.norm(), 0.0, 1e-12 * item.rest_length));
  }
  REQUIRE(limited > 100);
}

TEST_CASE("the spring limit keeps the centre of mass and never moves a pinned end", "[lab05][pts=1]") {
  // Σ m Δx = 0, multiplied through by w_i w_j so that a pinned end needs no
  // division: w_j Δx_i + w_i Δx_j = 0.
  for (const SpringCase& item : random_spring_cases(13, 1.0, 200)) {
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length,
            item.sigma_min, item.sigma_max);
    const DistanceCorrection correction = limit_spring_case(item);
    const double size = (item.x_i - item.x_j).norm() * (item.inv_mass_i + item.inv_mass_j);
    REQUIRE(cl::test::near((item.inv_mass_j * correction.dx_i + item.inv_mass_i * correction.dx_j).norm(), 0.0, 1e-12 * size));

    // End i pinned: it stays exactly where it is, end j takes the whole correction.
    SpringCase pinned = item;
    pinned.inv_mass_i = 0.0;
    const DistanceCorrection one_pinned = limit_spring_case(pinned);
    REQUIRE(cl::test::near(one_pinned.dx_i, Vector3d::Zero(), 0.0, "one_pinned.dx_i"));
    const double target = std::clamp(sigma_of(item), item.sigma_min, item.sigma_max) * item.rest_length;
    REQUIRE(cl::test::near_rel(length_after(pinned, one_pinned), target, 1e-12));

    // Both pinned: nothing moves.
    pinned.inv_mass_j = 0.0;
    const DistanceCorrection both_pinned = limit_spring_case(pinned);
    REQUIRE(cl::test::near(both_pinned.dx_i, Vector3d::Zero(), 0.0, "both_pinned.dx_i"));
    REQUIRE(cl::test::near(both_pinned.dx_j, Vector3d::Zero(), 0.0, "both_pinned.dx_j"));
  }
  // Coincident ends: σ = 0 is below the band, but there is no direction: a no-op.
  const DistanceCorrection coincident = limit_spring(Vector3d(1, 2, 3), Vector3d(1, 2, 3), 1.0, 2.0, 0.5, 0.9, 1.1);
  REQUIRE(cl::test::near(coincident.dx_i, Vector3d::Zero(), 0.0, "coincident.dx_i"));
  REQUIRE(cl::test::near(coincident.dx_j, Vector3d::Zero(), 0.0, "coincident.dx_j"));
}

TEST_CASE("the spring limit follows the two formulas of the notes for an unpinned spring", "[lab05][pts=1]") {
  //   Δx_i = −w_i/(w_i + w_j) (ℓ − σ₀L) n,   Δx_j = +w_j/(w_i + w_j) (ℓ − σ₀L) n
  int checked = 0;
  for (const SpringCase& item : random_spring_cases(17, 1.0, 300)) {
    const Vector3d d = item.x_i - item.x_j;
    const double length = d.norm();
    const Vector3d n = d / length;
    const double sigma0 = std::clamp(length / item.rest_length, item.sigma_min, item.sigma_max);
    const double excess = length - sigma0 * item.rest_length;
    const double w_sum = item.inv_mass_i + item.inv_mass_j;
    const Vector3d expected_i = -(item.inv_mass_i / w_sum) * excess * n;
    const Vector3d expected_j = (item.inv_mass_j / w_sum) * excess * n;
    CAPTURE(item.x_i.transpose(), item.x_j.transpose(), item.inv_mass_i, item.inv_mass_j, item.rest_length,
            item.sigma_min, item.sigma_max, sigma0, excess);
    const DistanceCorrection correction = limit_spring_case(item);
    // Round-off: relative to the correction, plus a few ulps of the length
    // (inside the band ℓ − σ₀L is itself round-off, and the answer is zero).
    const double tolerance = 1e-12 * std::abs(excess) + 1e-15 * length;
    REQUIRE(cl::test::near(correction.dx_i, expected_i, tolerance));
    REQUIRE(cl::test::near(correction.dx_j, expected_j, tolerance));
    checked += std::abs(excess) > 1e-9;
  }
  REQUIRE(checked > 150);
}
