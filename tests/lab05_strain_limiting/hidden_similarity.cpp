// Hidden graded test for lab05.3 (run only by the Gradescope bundle, shown to
// the student after grades are published): the stretch limiter does not care
// where a triangle is, how it is turned, or in what unit it is measured.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "strain_limiting.h"
#include "tests/support/checks.h"
#include "triangles.h"

TEST_CASE("the stretch limiter of a turned moved and scaled triangle gives the turned and scaled corrections",
          "[lab05][pts=1][hidden]") {
  // F = D_s D_m⁻¹ is unchanged when both the triangle and its rest shape are
  // scaled by s, and the frame turns with the triangle, so for x' = s R x + t
  // with rest s·(rest): Δx' = s R Δx (to round-off).
  std::mt19937_64 rng(505);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int limited = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Matrix3d rest_corners = lab05_test::random_triangle(rng, 1.0);
    const Eigen::Matrix3d corners = lab05_test::random_triangle(rng, 1.0);
    const Eigen::Vector3d inv_mass = lab05_test::random_inverse_masses(rng);
    const double s = std::pow(10.0, 2.0 * unit(rng));
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(3.0 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(unit(rng), unit(rng), unit(rng));
    CAPTURE(trial, rest_corners, corners, inv_mass.transpose(), s, rotation, shift.transpose());
    const cl::lab05::TriangleRest rest = cl::lab05::make_triangle_rest(rest_corners);
    const Eigen::Matrix3d moved_rest_corners = s * rest_corners;
    const cl::lab05::TriangleRest scaled_rest = cl::lab05::make_triangle_rest(moved_rest_corners);
    const Eigen::Matrix3d moved = ((s * rotation) * corners).colwise() + s * shift;
    const Eigen::Matrix3d correction = cl::lab05::limit_triangle_stretch(corners, inv_mass, rest, 0.9, 1.1);
    const Eigen::Matrix3d moved_correction = cl::lab05::limit_triangle_stretch(moved, inv_mass, scaled_rest, 0.9, 1.1);
    if (!correction.isZero(0.0)) ++limited;
    const Eigen::Matrix3d expected = (s * rotation) * correction;
    REQUIRE(cl::test::near(moved_correction, expected, 1e-11 * s * (1.0 + corners.cwiseAbs().maxCoeff()), "corner"));
  }
  REQUIRE(limited > 20);  // most random triangles are outside the band
}
