// Graded test for lab05.1–lab05.3: every limiter rejects what the header says it
// rejects, with std::invalid_argument, and accepts the edge of what is valid.
#include <limits>
#include <stdexcept>

#include "tests/support/catch.h"

#include "strain_limiting.h"

using Eigen::Matrix3d;
using Eigen::Vector3d;

TEST_CASE("every limiter rejects a bad band a bad rest shape and a bad inverse mass", "[lab05][pts=1]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Vector3d x_i(0, 0, 0), x_j(1.5, 0, 0);
  Matrix3d corners;
  corners << 0, 1.5, 0,  //
      0, 0, 1,           //
      0, 0, 0;
  Matrix3d rest_corners;
  rest_corners << 0, 1, 0,  //
      0, 0, 1,              //
      0, 0, 0;
  const cl::lab05::TriangleRest rest = cl::lab05::make_triangle_rest(rest_corners);
  const Vector3d ones(1, 1, 1);

  // Valid edges: an equality band σ_min = σ_max, a pinned end.
  REQUIRE_NOTHROW(cl::lab05::limit_spring(x_i, x_j, 0.0, 1.0, 1.0, 1.0, 1.0));
  REQUIRE_NOTHROW(cl::lab05::limit_triangle_area(corners, Vector3d(0, 1, 1), 0.5, 1.0, 1.0));
  REQUIRE_NOTHROW(cl::lab05::limit_triangle_stretch(corners, Vector3d(0, 1, 1), rest, 1.0, 1.0));

  const double bad_bands[][2] = {{0.0, 1.1}, {-0.5, 1.1}, {nan, 1.1}, {inf, inf}, {0.9, nan}, {0.9, inf},
                                 {1.2, 1.1}};
  for (const auto& band : bad_bands) {
    CAPTURE(band[0], band[1]);
    REQUIRE_THROWS_AS(cl::lab05::limit_spring(x_i, x_j, 1.0, 1.0, 1.0, band[0], band[1]), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_area(corners, ones, 0.5, band[0], band[1]), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_stretch(corners, ones, rest, band[0], band[1]),
                      std::invalid_argument);
  }
  for (const double rest_length : {0.0, -1.0, nan, inf}) {
    CAPTURE(rest_length);
    REQUIRE_THROWS_AS(cl::lab05::limit_spring(x_i, x_j, 1.0, 1.0, rest_length, 0.9, 1.1), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_area(corners, ones, rest_length, 0.9, 1.1), std::invalid_argument);
    cl::lab05::TriangleRest bad_rest = rest;
    bad_rest.area = rest_length;
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_stretch(corners, ones, bad_rest, 0.9, 1.1), std::invalid_argument);
  }
  cl::lab05::TriangleRest nan_rest = rest;
  nan_rest.inverse_shape(0, 1) = nan;
  REQUIRE_THROWS_AS(cl::lab05::limit_triangle_stretch(corners, ones, nan_rest, 0.9, 1.1), std::invalid_argument);
  nan_rest = rest;  // D_m is used too (the rest corners): a NaN there throws as well
  nan_rest.shape(1, 0) = nan;
  REQUIRE_THROWS_AS(cl::lab05::limit_triangle_stretch(corners, ones, nan_rest, 0.9, 1.1), std::invalid_argument);
  for (const double inv_mass : {-1.0, nan, inf}) {
    CAPTURE(inv_mass);
    REQUIRE_THROWS_AS(cl::lab05::limit_spring(x_i, x_j, inv_mass, 1.0, 1.0, 0.9, 1.1), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_spring(x_i, x_j, 1.0, inv_mass, 1.0, 0.9, 1.1), std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_area(corners, Vector3d(1, inv_mass, 1), 0.5, 0.9, 1.1),
                      std::invalid_argument);
    REQUIRE_THROWS_AS(cl::lab05::limit_triangle_stretch(corners, Vector3d(1, 1, inv_mass), rest, 0.9, 1.1),
                      std::invalid_argument);
  }
}
