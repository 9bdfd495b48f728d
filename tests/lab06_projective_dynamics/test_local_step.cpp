// Graded test for lab06.1, local_step: each spring projected onto its rest length.
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "projective_dynamics.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

TEST_CASE("the local step gives d of length L along x_i - x_j and a documented d for coincident ends",
          "[lab06][pts=2]") {
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> rest(0.1, 3.0);
  // Ordinary separations: exact length and direction, to round-off.
  for (const double scale : {1e-6, 1.0, 1e6}) {
    const int n = 6;
    const Eigen::Matrix3Xd x = scale * Eigen::Matrix3Xd::NullaryExpr(3, n, [&]() { return unit(rng); });
    std::vector<cl::Spring> springs;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (i != j) springs.push_back({i, j, (i + j) % 4 == 0 ? 0.0 : scale * rest(rng), 1.0});
      }
    }
    CAPTURE(scale, x);
    const Eigen::Matrix3Xd d = cl::lab06::local_step(x, springs);
    REQUIRE(d.rows() == 3);
    REQUIRE(d.cols() == static_cast<Eigen::Index>(springs.size()));
    for (std::size_t e = 0; e < springs.size(); ++e) {
      const cl::Spring& spring = springs[e];
      const Vector3d projected = d.col(static_cast<Eigen::Index>(e));
      const Vector3d edge = x.col(spring.i) - x.col(spring.j);
      CAPTURE(e, spring.i, spring.j, spring.rest_length, projected.transpose(), edge.transpose());
      if (spring.rest_length == 0.0) {
        REQUIRE(projected == Vector3d::Zero());
        continue;
      }
      REQUIRE(cl::test::near_rel(projected.norm(), spring.rest_length, 1e-14));
      // Same direction: d·edge = L‖edge‖ and d × edge = 0.
      REQUIRE(cl::test::near_rel(projected.dot(edge), spring.rest_length * edge.norm(), 1e-14));
      REQUIRE(cl::test::near(projected.cross(edge).norm(), 0.0, 1e-14 * spring.rest_length * edge.norm()));
    }
  }
  // Coincident ends — the computed length is 0 (projective_dynamics.h) —:
  // d = L (1, 0, 0) exactly. Ends 1e-160 m apart (subnormal squared length,
  // the length off by up to 1e-3) and 1e-170 m apart (squared length 0:
  // coincident by the rule): finite, never NaN, of length L.
  Eigen::Matrix3Xd x(3, 4);
  x.col(0) = Vector3d(0.3, -0.2, 0.7);
  x.col(1) = x.col(0);
  x.col(2) = Vector3d(1e-160, -1e-160, 1e-160);
  x.col(3) = Vector3d(1e-170, 0.0, -1e-170);
  const std::vector<cl::Spring> close{{0, 1, 0.25, 1.0}, {1, 0, 2.0, 1.0}, {2, 3, 0.5, 1.0}, {3, 2, 0.5, 1.0},
                                      {0, 1, 0.0, 1.0}};
  CAPTURE(x);
  const Eigen::Matrix3Xd d = cl::lab06::local_step(x, close);
  CAPTURE(d);
  REQUIRE(d.col(0) == Vector3d(0.25, 0.0, 0.0));
  REQUIRE(d.col(1) == Vector3d(2.0, 0.0, 0.0));
  REQUIRE(d.allFinite());
  REQUIRE(cl::test::near_rel(d.col(2).norm(), 0.5, 1e-3));
  REQUIRE(cl::test::near_rel(d.col(3).norm(), 0.5, 1e-3));
  REQUIRE(d.col(4) == Vector3d::Zero());
  // A spring index outside the positions is a bad argument.
  REQUIRE_THROWS_AS(cl::lab06::local_step(x, {{0, 4, 1.0, 1.0}}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab06::local_step(x, {{-1, 2, 1.0, 1.0}}), std::invalid_argument);
}
