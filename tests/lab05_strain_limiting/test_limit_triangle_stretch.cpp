// Graded tests for lab05.3, limit_triangle_stretch: the singular values of the
// new F in the band, the centroid and the rotation of F kept, and a turned-over
// and a zero-area triangle handled as strain_limiting.h says, and two or three
// pinned corners left alone.
#include <algorithm>
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "strain_limiting.h"
#include "triangles.h"
#include "tests/support/checks.h"

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using F32 = Eigen::Matrix<double, 3, 2>;

namespace {

struct StretchCase {
  Matrix3d corners;
  Vector3d inv_mass;
  cl::lab05::TriangleRest rest;
  double sigma_min, sigma_max;
};

// A random rest triangle and a random current one: any triangle is a
// deformation of any other, with principal stretches from well below to well
// above the bands.
StretchCase random_stretch_case(std::mt19937_64& rng, double scale, int index) {
  const double bands[3][2] = {{0.9, 1.1}, {0.5, 2.0}, {1.0, 1.0}};
  StretchCase item;
  item.rest = cl::lab05::make_triangle_rest(lab05_test::random_triangle(rng, scale));
  item.corners = lab05_test::random_triangle(rng, scale);
  item.inv_mass = lab05_test::random_inverse_masses(rng);
  item.sigma_min = bands[index % 3][0];
  item.sigma_max = bands[index % 3][1];
  return item;
}

Matrix3d limit_stretch_case(const StretchCase& item) {
  return cl::lab05::limit_triangle_stretch(item.corners, item.inv_mass, item.rest, item.sigma_min, item.sigma_max);
}

}  // namespace

TEST_CASE("the stretch limit puts both singular values of F in the band", "[lab05][pts=2]") {
  std::mt19937_64 rng(31);
  int moved = 0, untouched = 0;
  for (const double scale : {1e-2, 1.0, 1e2}) {
    for (int c = 0; c < 300; ++c) {
      StretchCase item = random_stretch_case(rng, scale, c);
      if (c % 7 == 6) item.corners = Eigen::AngleAxisd(1.0 + c, Vector3d(1, 2, 3).normalized()) * item.corners;
      const Vector2d before = lab05_test::singular_values(lab05_test::world_deformation(item.corners, item.rest));
      const Vector2d expected = before.cwiseMax(item.sigma_min).cwiseMin(item.sigma_max);
      CAPTURE(scale, item.corners, item.rest.shape, item.inv_mass.transpose(), item.sigma_min, item.sigma_max,
              before.transpose());
      const Matrix3d correction = limit_stretch_case(item);
      const Vector2d after =
          lab05_test::singular_values(lab05_test::world_deformation(item.corners + correction, item.rest));
      CAPTURE(after.transpose(), expected.transpose());
      REQUIRE(cl::test::near_rel(after[0], expected[0], 1e-12));
      REQUIRE(cl::test::near_rel(after[1], expected[1], 1e-12));
      moved += correction != Matrix3d::Zero();
    }
  }
  REQUIRE(moved > 600);

  // A triangle whose F is inside the band, rigidly moved: exactly untouched.
  for (int c = 0; c < 50; ++c) {
    StretchCase item = random_stretch_case(rng, 1.0, 0);
    Matrix3d rest_corners = Matrix3d::Zero();
    rest_corners.block<2, 2>(0, 1) = item.rest.shape;
    Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
    stretch(0, 0) = 1.05;
    stretch(1, 1) = 0.93;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.3 * c, Vector3d(3, -1, 2).normalized()).toRotationMatrix();
    item.corners = (rotation * stretch * rest_corners).colwise() + Vector3d(c, -c, 0.5);
    CAPTURE(item.corners, item.rest.shape);
    REQUIRE(limit_stretch_case(item) == Matrix3d::Zero());
    ++untouched;
  }
  REQUIRE(untouched == 50);
}

TEST_CASE("the stretch limit keeps the mass-weighted centroid and the rotation of F", "[lab05][pts=1]") {
  std::mt19937_64 rng(37);
  for (int c = 0; c < 300; ++c) {
    StretchCase item = random_stretch_case(rng, 1.0, c);
    if (c % 5 == 4) item.inv_mass[c % 3] = 0.0;  // one pinned corner: it is the centroid
    CAPTURE(item.corners, item.rest.shape, item.inv_mass.transpose(), item.sigma_min, item.sigma_max);
    const Matrix3d correction = limit_stretch_case(item);
    const Vector3d weights = lab05_test::centroid_weights(item.inv_mass);
    const double size = (item.corners.colwise() - item.corners.rowwise().mean()).norm() * weights.sum();
    REQUIRE(cl::test::near((correction * weights).norm(), 0.0, 1e-12 * size));
    for (int a = 0; a < 3; ++a) {
      if (item.inv_mass[a] == 0.0) {
        CAPTURE(a);
        REQUIRE(cl::test::near(correction.col(a).norm(), 0.0, 1e-12 * item.corners.norm()));
      }
    }
    // The polar factor R = U Vᵀ of F (3 × 2) is unchanged.
    const F32 rotation_before = lab05_test::rotation_of(lab05_test::world_deformation(item.corners, item.rest));
    const F32 rotation_after =
        lab05_test::rotation_of(lab05_test::world_deformation(item.corners + correction, item.rest));
    REQUIRE(cl::test::near(rotation_after, rotation_before, 1e-12));
  }
}

TEST_CASE("the stretch limit handles a turned-over and a zero-area triangle as the header says", "[lab05][pts=1]") {
  // Rest: a right triangle in the x-y plane.
  Matrix3d rest_corners;
  rest_corners << 0, 1, 0,  //
      0, 0, 1,              //
      0, 0, 0;
  const cl::lab05::TriangleRest rest = cl::lab05::make_triangle_rest(rest_corners);
  const Vector3d inv_mass(1.0, 2.0, 0.5);

  // Turned over: x_k pushed through the edge x_i x_j (mirrored in the plane).
  // In 3-D that is the rest triangle seen from behind: nothing to limit.
  Matrix3d turned = rest_corners;
  turned(1, 2) = -1.0;
  const Matrix3d none = cl::lab05::limit_triangle_stretch(turned, inv_mass, rest, 0.9, 1.1);
  CAPTURE(turned, none);
  REQUIRE(none.allFinite());
  REQUIRE(cl::test::near(none.cwiseAbs().maxCoeff(), 0.0, 1e-12));

  // Turned over and stretched 1.6 × along x, squeezed 0.5 × along y: limited
  // like any other, and it stays turned over (same normal as its input).
  Matrix3d turned_stretched = turned;
  turned_stretched.row(0) *= 1.6;
  turned_stretched.row(1) *= 0.5;
  const Matrix3d correction = cl::lab05::limit_triangle_stretch(turned_stretched, inv_mass, rest, 0.9, 1.1);
  const Matrix3d after = turned_stretched + correction;
  CAPTURE(turned_stretched, correction);
  REQUIRE(after.allFinite());
  const Vector2d stretches = lab05_test::singular_values(lab05_test::world_deformation(after, rest));
  REQUIRE(cl::test::near_rel(stretches[0], 1.1, 1e-12));
  REQUIRE(cl::test::near_rel(stretches[1], 0.9, 1e-12));
  REQUIRE(cl::test::near(lab05_test::normal_of(after).dot(lab05_test::normal_of(turned_stretched)), 1.0, 1e-12));

  // Zero area: collinear corners (stretched far beyond the band), two
  // coincident corners, all three coincident. No frame: exactly zero, no NaN.
  Matrix3d collinear;
  collinear << 0, 2, 5,  //
      0, 0, 0,           //
      0, 0, 0;
  Matrix3d two_coincident = collinear;
  two_coincident.col(2) = two_coincident.col(1);
  const Matrix3d all_coincident = Vector3d(0.5, -1, 2).replicate(1, 3);
  for (const Matrix3d& corners : {collinear, two_coincident, all_coincident}) {
    CAPTURE(corners);
    const Matrix3d zero = cl::lab05::limit_triangle_stretch(corners, inv_mass, rest, 0.9, 1.1);
    REQUIRE(zero == Matrix3d::Zero());
  }
}

TEST_CASE("the stretch limit leaves a triangle with two or three pinned corners alone", "[lab05][pts=1]") {
  // The weights ω = (w_j w_k, w_i w_k, w_i w_j) then sum to 0: no centroid to
  // scale about, and nothing a limiter may move (a curtain pinned along its
  // top row has such triangles). Stretched 1.6 × far outside the band, so
  // only that rule returns zeros here.
  Matrix3d rest_corners;
  rest_corners << 0, 1, 0,  //
      0, 0, 1,              //
      0, 0, 0;
  const cl::lab05::TriangleRest rest = cl::lab05::make_triangle_rest(rest_corners);
  Matrix3d stretched = rest_corners;
  stretched.row(0) *= 1.6;
  for (const Vector3d& inv_mass : {Vector3d(0, 0, 1), Vector3d(0, 2, 0), Vector3d(0.5, 0, 0), Vector3d(0, 0, 0)}) {
    CAPTURE(inv_mass.transpose(), stretched);
    const Matrix3d zero = cl::lab05::limit_triangle_stretch(stretched, inv_mass, rest, 0.9, 1.1);
    CAPTURE(zero);
    REQUIRE(zero == Matrix3d::Zero());
  }
}
