// Graded tests for lab09.1, geometric_stiffness: K_g is the derivative of the
// constraint force Jᵀλ at fixed λ (central differences), and the compression
// treatment (dropped, so that −K_g is positive semidefinite).
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>
#include "tests/support/catch.h"

#include "constrained.h"
#include "geometric_stiffness.h"
#include "lab09_scenes.h"
#include "tests/support/checks.h"

using cl::lab09::Compression;

namespace {

// Jᵀλ over the movable unknowns (lab 07's reference Jacobian), stacked.
Eigen::VectorXd constraint_force(const Eigen::Matrix3Xd& x, const std::vector<cl::Spring>& springs,
                                 const Eigen::VectorXd& lambda, const cl::MovableMap& map) {
  const cl::SparseMatrix jacobian = cl::lab07::constraint_jacobian(x, springs, map);
  return jacobian.transpose() * lambda;
}

Eigen::VectorXd random_lambda(std::mt19937_64& rng, std::size_t m, double low, double high) {
  std::uniform_real_distribution<double> value(low, high);
  Eigen::VectorXd lambda(static_cast<Eigen::Index>(m));
  for (Eigen::Index e = 0; e < lambda.size(); ++e) lambda[e] = value(rng);
  return lambda;
}

double hard(int) { return cl::kInfiniteStiffness; }

}  // namespace

TEST_CASE("K_g matches central finite differences of J transpose lambda to 1e-6", "[lab09][pts=3]") {
  // Every movable coordinate is moved by ±h and the change of Jᵀ(x)λ (λ fixed,
  // both signs, |λ| <= 5 N) divided by 2h is one column of K_g. Springs are at
  // least 0.3 m long, so the truncation error O(h² |λ|/ℓ³) is about 1e-8 at
  // h = 1e-5 and round-off about 1e-10: 1e-6 has room. Compression::kKeep:
  // the exact derivative, compressed constraints included.
  const double h = 1e-5;
  for (std::uint64_t seed = 900; seed < 908; ++seed) {
    std::mt19937_64 rng(seed);
    const int n = 3 + static_cast<int>(seed % 5);
    const int pinned = static_cast<int>(seed % 2);
    const lab09_test::RandomScene scene = lab09_test::random_scene(rng, n, pinned, n, hard);
    const Eigen::VectorXd lambda = random_lambda(rng, scene.springs.size(), -5.0, 5.0);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    CAPTURE(seed, n, pinned, scene.text, lambda.transpose());

    const cl::SparseMatrix stiffness =
        cl::lab09::geometric_stiffness(scene.particles.x, scene.springs, lambda, map, Compression::kKeep);
    const Eigen::Index size = 3 * map.unknowns();
    REQUIRE(stiffness.rows() == size);
    REQUIRE(stiffness.cols() == size);

    Eigen::MatrixXd expected(size, size);
    for (int u = 0; u < map.unknowns(); ++u) {
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3Xd plus = scene.particles.x, minus = scene.particles.x;
        plus(c, map.particle_of[static_cast<std::size_t>(u)]) += h;
        minus(c, map.particle_of[static_cast<std::size_t>(u)]) -= h;
        expected.col(3 * u + c) = (constraint_force(plus, scene.springs, lambda, map) -
                                   constraint_force(minus, scene.springs, lambda, map)) /
                                  (2.0 * h);
      }
    }
    const Eigen::MatrixXd actual(stiffness);
    REQUIRE(cl::test::near(actual, expected, 1e-6));
    REQUIRE(cl::test::near(actual, Eigen::MatrixXd(actual.transpose()), 1e-14));
  }
}

TEST_CASE("K_g drops compressed constraints and coincident ends and rejects a bad lambda", "[lab09][pts=2]") {
  for (std::uint64_t seed = 920; seed < 926; ++seed) {
    std::mt19937_64 rng(seed);
    const int n = 4 + static_cast<int>(seed % 4);
    const lab09_test::RandomScene scene = lab09_test::random_scene(rng, n, 1, n, hard);
    const Eigen::VectorXd lambda = random_lambda(rng, scene.springs.size(), -50.0, 50.0);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const Eigen::Matrix3Xd& x = scene.particles.x;
    CAPTURE(seed, n, scene.text, lambda.transpose());

    // kDrop is kKeep with every compression (λ > 0) replaced by 0.
    const Eigen::MatrixXd dropped(cl::lab09::geometric_stiffness(x, scene.springs, lambda, map, Compression::kDrop));
    const Eigen::VectorXd tension = lambda.cwiseMin(0.0);
    const Eigen::MatrixXd kept_tension(
        cl::lab09::geometric_stiffness(x, scene.springs, tension, map, Compression::kKeep));
    REQUIRE(cl::test::near(dropped, kept_tension, 1e-12));
    // Each tension block −λ(I − nnᵀ)/ℓ is positive semidefinite, and so is the sum −K_g.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(-dropped, Eigen::EigenvaluesOnly);
    const double scale = std::max(1.0, dropped.cwiseAbs().maxCoeff());
    CAPTURE(eigen.eigenvalues().transpose());
    REQUIRE(eigen.eigenvalues().minCoeff() >= -1e-12 * scale);
    // Pure compression: nothing at all.
    const Eigen::VectorXd compression = lambda.cwiseAbs().array() + 1.0;
    const Eigen::MatrixXd none(cl::lab09::geometric_stiffness(x, scene.springs, compression, map, Compression::kDrop));
    REQUIRE(none.rows() == 3 * map.unknowns());
    REQUIRE(none.cwiseAbs().maxCoeff() == 0.0);
  }

  SECTION("coincident ends contribute nothing") {
    cl::Particles particles;
    particles.x.resize(3, 3);
    particles.x << 0.0, 1.0, 1.0,  //
        0.0, 0.0, 0.0,             //
        0.0, 0.0, 0.0;             // particles 1 and 2 coincide
    particles.inv_mass = Eigen::Vector3d(0.0, 1.0, 2.0);
    const std::vector<cl::Spring> one{{0, 1, 1.0}};
    const std::vector<cl::Spring> both{{0, 1, 1.0}, {1, 2, 0.0}};
    const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
    for (const Compression compression : {Compression::kKeep, Compression::kDrop}) {
      const Eigen::MatrixXd without(
          cl::lab09::geometric_stiffness(particles.x, one, Eigen::VectorXd::Constant(1, -3.0), map, compression));
      const Eigen::MatrixXd with(cl::lab09::geometric_stiffness(particles.x, both, Eigen::Vector2d(-3.0, -7.0), map,
                                                                compression));
      REQUIRE(with.allFinite());
      REQUIRE(cl::test::near(with, without, 0.0));
    }
  }

  SECTION("a lambda of the wrong size or not finite, a bad index, i == j throw std::invalid_argument") {
    Eigen::Matrix3Xd x(3, 3);
    x << 0.0, 1.0, 2.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0;
    const cl::MovableMap map = cl::make_movable_map(Eigen::Vector3d(0.0, 1.0, 1.0));
    const std::vector<cl::Spring> springs{{0, 1, 1.0}, {1, 2, 1.0}};
    const double nan = std::numeric_limits<double>::quiet_NaN();
    using cl::lab09::geometric_stiffness;
    REQUIRE_THROWS_AS(geometric_stiffness(x, springs, Eigen::VectorXd::Zero(3), map, Compression::kDrop),
                      std::invalid_argument);
    REQUIRE_THROWS_AS(geometric_stiffness(x, springs, Eigen::Vector2d(-1.0, nan), map, Compression::kKeep),
                      std::invalid_argument);
    REQUIRE_THROWS_AS(geometric_stiffness(x, {{0, 3, 1.0}}, Eigen::VectorXd::Constant(1, -1.0), map,
                                          Compression::kDrop),
                      std::invalid_argument);
    REQUIRE_THROWS_AS(geometric_stiffness(x, {{1, 1, 1.0}}, Eigen::VectorXd::Constant(1, -1.0), map,
                                          Compression::kDrop),
                      std::invalid_argument);
  }
}
