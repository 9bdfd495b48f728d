// Graded tests for lab07.2: the KKT matrix and right-hand side as written in
// constrained.h, block by block.
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "constrained.h"
#include "scenes_for_tests.h"
#include "step.h"
#include "tests/support/checks.h"


namespace {

cl::lab07::LinearizedStep random_step(std::uint64_t seed, bool soft, std::string& text) {
  std::mt19937_64 rng(seed);
  const lab07_test::RandomScene scene = lab07_test::random_scene(rng, 7, soft ? 2 : 1, soft ? 5 : 0);
  text = scene.text;
  cl::lab07::StepSettings settings;
  settings.dt = 0.02;
  settings.gravity = Eigen::Vector3d(0.5, -9.81, 0.25);
  return cl::lab07::linearize(scene.particles, scene.springs, cl::make_movable_map(scene.particles.inv_mass),
                              settings);
}

}  // namespace

TEST_CASE("the KKT matrix is M and -dt J^T over dt J and C with right-hand side M(v + dt g) and -phi",
          "[lab07][pts=1]") {
  for (const std::uint64_t seed : {11u, 12u, 13u}) {
    std::string text;
    const cl::lab07::LinearizedStep step = random_step(seed, true, text);
    CAPTURE(seed, text);
    const cl::lab07::KktSystem system = cl::lab07::kkt_system(step);
    const Eigen::Index n3 = step.velocity.size(), m = step.phi.size();
    REQUIRE(system.matrix.rows() == n3 + m);
    REQUIRE(system.matrix.cols() == n3 + m);
    REQUIRE(system.rhs.size() == n3 + m);
    const lab07_test::DenseKkt expected = lab07_test::dense_kkt(step);
    REQUIRE(cl::test::near(Eigen::MatrixXd(system.matrix), expected.matrix,
                           1e-12 * expected.matrix.cwiseAbs().maxCoeff()));
    REQUIRE(cl::test::near(system.rhs, expected.rhs, 1e-12 * expected.rhs.cwiseAbs().maxCoeff(), "rhs"));
  }
}

TEST_CASE("an all-hard scene builds no compliance block and only non-zero compliances are stored",
          "[lab07][pts=1]") {
  std::string text;
  cl::lab07::LinearizedStep step = random_step(21, false, text);
  CAPTURE(text);
  REQUIRE(step.compliance.size() == 0);  // given code: every spring hard
  const Eigen::Index n3 = step.velocity.size(), m = step.phi.size();
  cl::lab07::KktSystem system = cl::lab07::kkt_system(step);
  REQUIRE(system.matrix.rows() == n3 + m);
  // M's diagonal plus the two copies of J: nothing in the lower-right block.
  CHECK(system.matrix.nonZeros() == n3 + 2 * step.jacobian.nonZeros());
  CHECK(Eigen::MatrixXd(system.matrix).bottomRightCorner(m, m).isZero(0.0));

  // Compliance on every second constraint only: that many stored entries more.
  step.compliance = Eigen::VectorXd::Zero(m);
  Eigen::Index soft = 0;
  for (Eigen::Index e = 0; e < m; e += 2, ++soft) step.compliance[e] = 1e-4 * static_cast<double>(e + 1);
  system = cl::lab07::kkt_system(step);
  CHECK(system.matrix.nonZeros() == n3 + 2 * step.jacobian.nonZeros() + soft);
  const Eigen::MatrixXd lower_right = Eigen::MatrixXd(system.matrix).bottomRightCorner(m, m);
  CHECK(lower_right.isApprox(Eigen::MatrixXd(step.compliance.asDiagonal()), 1e-15));

  // Bad sizes and steps throw.
  cl::lab07::LinearizedStep bad = step;
  bad.phi.resize(m + 1);
  CHECK_THROWS_AS(cl::lab07::kkt_system(bad), std::invalid_argument);
  bad = step;
  bad.dt = 0.0;
  CHECK_THROWS_AS(cl::lab07::kkt_system(bad), std::invalid_argument);
  bad = step;
  bad.inv_mass[0] = 0.0;
  CHECK_THROWS_AS(cl::lab07::kkt_system(bad), std::invalid_argument);
}
