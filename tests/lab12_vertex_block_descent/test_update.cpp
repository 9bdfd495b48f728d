// Graded tests of lab12.2: the vertex update solves H Δx = f, is a no-op for
// pinned vertices and near-singular or non-finite blocks, and (with lab12.1)
// never raises g.
#include <cmath>
#include <limits>
#include <random>

#include <catch2/catch.hpp>

#include "scenes.h"
#include "simulation.h"
#include "tests/support/checks.h"
#include "vbd.h"

TEST_CASE("the vertex update solves H dx = f and is a documented no-op where it cannot", "[lab12][pts=1]") {
  std::mt19937_64 rng(1202);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Matrix3d a = Eigen::Matrix3d::Random();
    const double size = std::pow(10.0, 6.0 * unit(rng));  // the units of k and m must not matter
    cl::lab12::VertexBlock block;
    block.hessian = size * (a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity());
    block.force = size * Eigen::Vector3d::Random();
    CAPTURE(trial, size);
    const Eigen::Vector3d step = cl::lab12::vertex_update(block, 0.7);
    REQUIRE(cl::test::near(Eigen::Vector3d(block.hessian * step), block.force, 1e-10 * block.force.norm()));
    REQUIRE(cl::lab12::vertex_update(block, 0.0) == Eigen::Vector3d::Zero());  // pinned
  }
  cl::lab12::VertexBlock singular;
  singular.force = Eigen::Vector3d(1.0, 2.0, 3.0);
  REQUIRE(cl::lab12::vertex_update(singular, 1.0) == Eigen::Vector3d::Zero());  // H = 0
  singular.hessian = Eigen::Vector3d(1.0, 0.0, 0.0) * Eigen::RowVector3d(1.0, 0.0, 0.0);  // rank 1
  REQUIRE(cl::lab12::vertex_update(singular, 1.0) == Eigen::Vector3d::Zero());
  singular.hessian = Eigen::Vector3d(1e8, 1.0, 1e-7).asDiagonal();  // |det| = 10 < 1e-12 · (1e8)³
  REQUIRE(cl::lab12::vertex_update(singular, 1.0) == Eigen::Vector3d::Zero());
  cl::lab12::VertexBlock bad;
  bad.hessian = Eigen::Matrix3d::Identity();
  bad.force = Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  REQUIRE(cl::lab12::vertex_update(bad, 1.0) == Eigen::Vector3d::Zero());
  bad.force = Eigen::Vector3d::Ones();
  bad.hessian(1, 1) = std::numeric_limits<double>::infinity();
  REQUIRE(cl::lab12::vertex_update(bad, 1.0) == Eigen::Vector3d::Zero());
  const Eigen::Matrix3d tiny = 1e-300 * Eigen::Matrix3d::Identity();  // well conditioned, Δx overflows
  bad.hessian = tiny;
  bad.force = Eigen::Vector3d::Constant(1e300);
  REQUIRE(cl::lab12::vertex_update(bad, 1.0) == Eigen::Vector3d::Zero());
}

TEST_CASE("g never increases over one vertex update with compressed springs", "[lab12][pts=1]") {
  // Rest lengths up to 3 times the current length and light particles: the
  // unclamped block is indefinite here, and its step can climb.
  std::mt19937_64 rng(1203);
  for (int trial = 0; trial < 8; ++trial) {
    cl::Particles start = lab12_test::random_particles(rng, 10);
    start.inv_mass[trial] = 0.0;
    const std::vector<cl::Spring> springs = lab12_test::random_springs(rng, start.x, 12, 0.3, 3.0, 1.0, 4.0);
    const double dt = trial % 2 ? 1.0 / 60.0 : 0.1;
    const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, springs, dt);
    const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(10, springs);
    const Eigen::Matrix3Xd y = cl::lab06::predict(start, Eigen::Vector3d(0.0, -9.81, 0.0), dt);
    Eigen::Matrix3Xd x = start.x;  // not y: the inertia term is not at its minimum either
    CAPTURE(trial, dt, start.x, start.v, start.inv_mass.transpose());
    for (int round = 0; round < 3; ++round) {
      for (int p = 0; p < 10; ++p) {
        const double before = cl::lab06::objective(problem, x, y);
        const Eigen::Vector3d held = x.col(p);
        x.col(p) += cl::lab12::vertex_update(cl::lab12::vertex_block(problem, adjacency, x, y, p), start.inv_mass[p]);
        const double after = cl::lab06::objective(problem, x, y);
        CAPTURE(trial, round, p, before, after);
        REQUIRE(cl::test::at_most("g after the update", after, before + 1e-13 * std::abs(before)));
        if (!(start.inv_mass[p] > 0.0)) REQUIRE(x.col(p) == held);
      }
    }
  }
}
