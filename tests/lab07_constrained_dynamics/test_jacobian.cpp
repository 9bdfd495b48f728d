// Graded tests for lab07.1: the constraint values φ and their sparse Jacobian
// over the movable unknowns.
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "constrained.h"
#include "scenes_for_tests.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

TEST_CASE("the Jacobian matches central differences of phi to 1e-7", "[lab07][pts=2]") {
  // ∂φ_e/∂x_(u,c) ≈ (φ_e(x + h e_(u,c)) − φ_e(x − h e_(u,c))) / 2h. The error is
  // h² times the third derivative (about 1/ℓ², ℓ >= 0.2 m) plus round-off ε/h.
  const double h = 1e-5;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    std::mt19937_64 rng(seed);
    const lab07_test::RandomScene scene = lab07_test::random_scene(rng, 12, 3, 10);
    CAPTURE(seed, scene.text);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const Eigen::MatrixXd jacobian = Eigen::MatrixXd(cl::lab07::constraint_jacobian(scene.particles.x, scene.springs, map));
    REQUIRE(jacobian.rows() == static_cast<Eigen::Index>(scene.springs.size()));
    REQUIRE(jacobian.cols() == 3 * map.unknowns());
    Eigen::MatrixXd numeric(jacobian.rows(), jacobian.cols());
    for (int u = 0; u < map.unknowns(); ++u) {
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3Xd plus = scene.particles.x, minus = scene.particles.x;
        plus(c, map.particle_of[static_cast<std::size_t>(u)]) += h;
        minus(c, map.particle_of[static_cast<std::size_t>(u)]) -= h;
        numeric.col(3 * u + c) = (cl::lab07::constraint_values(plus, scene.springs) -
                                  cl::lab07::constraint_values(minus, scene.springs)) / (2.0 * h);
      }
    }
    // Rows are springs, columns the stacked unknowns' coordinates (3u + c).
    REQUIRE(cl::test::near(jacobian, numeric, 1e-7));
  }
}

TEST_CASE("phi is length minus rest length and pinned or coincident ends leave no entries", "[lab07][pts=1]") {
  // Particles: 0 pinned, 1 and 2 movable, 3 pinned, 4 movable and coincident with 2.
  cl::Particles particles;
  particles.x.resize(3, 5);
  particles.x.col(0) = Vector3d(0, 0, 0);
  particles.x.col(1) = Vector3d(3, 4, 0);
  particles.x.col(2) = Vector3d(3, 4, 12);
  particles.x.col(3) = Vector3d(-1, 0, 0);
  particles.x.col(4) = Vector3d(3, 4, 12);
  particles.inv_mass.resize(5);
  particles.inv_mass << 0.0, 1.0, 2.0, 0.0, 0.5;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  const std::vector<cl::Spring> springs = {
      {0, 1, 4.0, cl::kInfiniteStiffness},  // pinned–movable, length 5
      {1, 2, 12.0, 100.0},                  // movable–movable, length 12
      {0, 3, 0.5, cl::kInfiniteStiffness},  // pinned–pinned, length 1
      {2, 4, 0.0, 10.0},                    // coincident
  };
  const Eigen::VectorXd phi = cl::lab07::constraint_values(particles.x, springs);
  REQUIRE(phi.size() == 4);
  CHECK(cl::test::near(phi[0], 1.0, 1e-15));
  CHECK(cl::test::near(phi[1], 0.0, 1e-15));
  CHECK(cl::test::near(phi[2], 0.5, 1e-15));
  CHECK(cl::test::near(phi[3], 0.0, 0.0));

  const cl::SparseMatrix jacobian = cl::lab07::constraint_jacobian(particles.x, springs, map);
  REQUIRE(jacobian.rows() == 4);
  REQUIRE(jacobian.cols() == 9);  // three unknowns: particles 1, 2, 4
  const Eigen::MatrixXd dense = Eigen::MatrixXd(jacobian);
  CAPTURE(dense);
  REQUIRE(dense.allFinite());
  // Row 0: only particle 1 (unknown 0) with +n = (3, 4, 0)/5; the pinned end has no columns.
  CHECK(dense.row(0).segment<3>(0).isApprox(Eigen::RowVector3d(0.6, 0.8, 0.0), 1e-15));
  CHECK(dense.row(0).segment<6>(3).isZero(0.0));
  // Row 1: +n at unknown 0, −n at unknown 1, n = (0, 0, −1).
  CHECK(dense.row(1).segment<3>(0).isApprox(Eigen::RowVector3d(0.0, 0.0, -1.0), 1e-15));
  CHECK(dense.row(1).segment<3>(3).isApprox(Eigen::RowVector3d(0.0, 0.0, 1.0), 1e-15));
  CHECK(dense.row(1).segment<3>(6).isZero(0.0));
  // Rows 2 (both ends pinned) and 3 (coincident ends) are empty.
  CHECK(dense.row(2).isZero(0.0));
  CHECK(dense.row(3).isZero(0.0));

  CHECK_THROWS_AS(cl::lab07::constraint_values(particles.x, {{0, 5, 1.0, 1.0}}), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab07::constraint_values(particles.x, {{1, 1, 1.0, 1.0}}), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab07::constraint_jacobian(particles.x, {{0, 1, -1.0, 1.0}}, map), std::invalid_argument);
}
