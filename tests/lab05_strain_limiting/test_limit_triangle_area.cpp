// Graded tests for lab05.2, limit_triangle_area: the area ratio in the band,
// the mass-weighted centroid, the shape (angles and normal), degenerate input.
#include <algorithm>
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "strain_limiting.h"
#include "triangles.h"
#include "tests/support/checks.h"

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

struct AreaCase {
  Matrix3d corners;
  Vector3d inv_mass;
  double rest_area, sigma_min, sigma_max;
};

// Area ratios A / A_rest from 0.2 to 5, three bands (one an equality).
AreaCase random_area_case(std::mt19937_64& rng, double scale, int index) {
  std::uniform_real_distribution<double> log_ratio(std::log(0.2), std::log(5.0));
  const double bands[3][2] = {{0.9, 1.1}, {0.5, 2.0}, {1.0, 1.0}};
  AreaCase item;
  item.corners = lab05_test::random_triangle(rng, scale);
  item.inv_mass = lab05_test::random_inverse_masses(rng);
  item.rest_area = lab05_test::area_of(item.corners) / std::exp(log_ratio(rng));
  item.sigma_min = bands[index % 3][0];
  item.sigma_max = bands[index % 3][1];
  return item;
}

Matrix3d limit_area_case(const AreaCase& item) {
  return cl::lab05::limit_triangle_area(item.corners, item.inv_mass, item.rest_area, item.sigma_min, item.sigma_max);
}

}  // namespace

TEST_CASE("the area limit brings the area ratio into the band and leaves degenerate triangles alone",
          "[lab05][pts=1]") {
  std::mt19937_64 rng(21);
  int moved = 0;
  for (const double scale : {1e-2, 1.0, 1e2}) {
    for (int c = 0; c < 200; ++c) {
      const AreaCase item = random_area_case(rng, scale, c);
      const double ratio = lab05_test::area_of(item.corners) / item.rest_area;
      const double expected = std::clamp(ratio, item.sigma_min * item.sigma_min, item.sigma_max * item.sigma_max);
      CAPTURE(scale, item.corners, item.inv_mass.transpose(), item.rest_area, item.sigma_min, item.sigma_max, ratio);
      const Matrix3d correction = limit_area_case(item);
      if (ratio == expected) REQUIRE(correction == Matrix3d::Zero());  // inside the band: untouched
      const Matrix3d after = item.corners + correction;
      REQUIRE(cl::test::near_rel(lab05_test::area_of(after) / item.rest_area, expected, 1e-12));
      moved += correction != Matrix3d::Zero();
    }
  }
  REQUIRE(moved > 300);

  // Zero area (collinear, coincident) and two pinned corners: all zeros.
  Matrix3d collinear;
  collinear << 0, 1, 3,  //
      0, 1, 3,           //
      0, 2, 6;
  const Matrix3d coincident = Vector3d(1, 2, 3).replicate(1, 3);
  for (const Matrix3d& corners : {collinear, coincident}) {
    CAPTURE(corners);
    const Matrix3d correction = cl::lab05::limit_triangle_area(corners, Vector3d(1, 2, 3), 0.5, 0.9, 1.1);
    REQUIRE(correction == Matrix3d::Zero());
  }
  AreaCase two_pinned = random_area_case(rng, 1.0, 0);
  two_pinned.rest_area = 10.0 * lab05_test::area_of(two_pinned.corners);
  two_pinned.inv_mass = Vector3d(0.0, 1.0, 0.0);
  REQUIRE(limit_area_case(two_pinned) == Matrix3d::Zero());
}

TEST_CASE("the area limit keeps the mass-weighted centroid and the angles", "[lab05][pts=1]") {
  std::mt19937_64 rng(23);
  for (int c = 0; c < 300; ++c) {
    AreaCase item = random_area_case(rng, 1.0, c);
    if (c % 5 == 4) item.inv_mass[c % 3] = 0.0;  // one pinned corner: it is the centroid
    CAPTURE(item.corners, item.inv_mass.transpose(), item.rest_area, item.sigma_min, item.sigma_max);
    const Matrix3d correction = limit_area_case(item);
    const Matrix3d after = item.corners + correction;
    // Σ m_a Δx_a = 0, written with ω_a = m_a w_i w_j w_k.
    const Vector3d weights = lab05_test::centroid_weights(item.inv_mass);
    const double size = (item.corners.colwise() - item.corners.rowwise().mean()).norm() * weights.sum();
    REQUIRE(cl::test::near((correction * weights).norm(), 0.0, 1e-12 * size));
    for (int a = 0; a < 3; ++a) {
      if (item.inv_mass[a] == 0.0) {
        CAPTURE(a);
        REQUIRE(cl::test::near(correction.col(a).norm(), 0.0, 1e-14 * item.corners.norm()));
      }
    }
    // Similar: the same angles, the same normal.
    REQUIRE(cl::test::near(lab05_test::angles_of(after), lab05_test::angles_of(item.corners), 1e-12));
    REQUIRE(cl::test::near(lab05_test::normal_of(after).dot(lab05_test::normal_of(item.corners)), 1.0, 1e-12));
  }
}
