// Graded tests of lab12.2 and lab12.3: the Newton step solves H d = f and is
// a no-op for pinned vertices and near-singular or non-finite blocks; the
// vertex update backtracks along it and (with lab12.1) never raises g.
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>
#include "tests/support/catch.h"

#include "scenes.h"
#include "simulation.h"
#include "tests/support/checks.h"
#include "vbd.h"

TEST_CASE("the Newton step solves H d = f and is a documented no-op where it cannot", "[lab12][pts=1]") {
  std::mt19937_64 rng(1202);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Matrix3d a = Eigen::Matrix3d::Random();
    const double size = std::pow(10.0, 6.0 * unit(rng));  // the units of k and m must not matter
    cl::lab12::VertexBlock block;
    block.hessian = size * (a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity());
    block.force = size * Eigen::Vector3d::Random();
    CAPTURE(trial, size);
    const Eigen::Vector3d step = cl::lab12::vertex_newton_step(block, 0.7);
    REQUIRE(cl::test::near(Eigen::Vector3d(block.hessian * step), block.force, 1e-10 * block.force.norm()));
    REQUIRE(cl::lab12::vertex_newton_step(block, 0.0) == Eigen::Vector3d::Zero());  // pinned
  }
  cl::lab12::VertexBlock singular;
  singular.force = Eigen::Vector3d(1.0, 2.0, 3.0);
  REQUIRE(cl::lab12::vertex_newton_step(singular, 1.0) == Eigen::Vector3d::Zero());  // H = 0
  singular.hessian = Eigen::Vector3d(1.0, 0.0, 0.0) * Eigen::RowVector3d(1.0, 0.0, 0.0);  // rank 1
  REQUIRE(cl::lab12::vertex_newton_step(singular, 1.0) == Eigen::Vector3d::Zero());
  singular.hessian = Eigen::Vector3d(1e8, 1.0, 1e-7).asDiagonal();  // |det| = 10 < 1e-12 · (1e8)³
  REQUIRE(cl::lab12::vertex_newton_step(singular, 1.0) == Eigen::Vector3d::Zero());
  cl::lab12::VertexBlock bad;
  bad.hessian = Eigen::Matrix3d::Identity();
  bad.force = Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  REQUIRE(cl::lab12::vertex_newton_step(bad, 1.0) == Eigen::Vector3d::Zero());
  bad.force = Eigen::Vector3d::Ones();
  bad.hessian(1, 1) = std::numeric_limits<double>::infinity();
  REQUIRE(cl::lab12::vertex_newton_step(bad, 1.0) == Eigen::Vector3d::Zero());
  const Eigen::Matrix3d tiny = 1e-300 * Eigen::Matrix3d::Identity();  // well conditioned, Δx overflows
  bad.hessian = tiny;
  bad.force = Eigen::Vector3d::Constant(1e300);
  REQUIRE(cl::lab12::vertex_newton_step(bad, 1.0) == Eigen::Vector3d::Zero());
}

namespace {

// The test's own Newton direction: lab 06's gradient and clamped Hessian
// block, solved densely (independent of lab12.1 and lab12.2).
struct Direction {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  double slope = 0.0;  // f·d
};

Direction newton_direction(const cl::lab06::Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                           int particle) {
  const int u = problem.map.unknown_of[static_cast<std::size_t>(particle)];
  if (u < 0) return {};
  const Eigen::VectorXd gradient = cl::lab06::newton_gradient(problem, x, y);
  const Eigen::MatrixXd hessian = Eigen::MatrixXd(cl::lab06::newton_hessian(problem, x, true));
  const Eigen::Vector3d force = -gradient.segment<3>(3 * u);
  const Eigen::Matrix3d block = hessian.block<3, 3>(3 * u, 3 * u);
  Direction direction;
  direction.d = block.ldlt().solve(force);
  direction.slope = force.dot(direction.d);
  return direction;
}

// Armijo's test as vbd.h states it, on the given vertex_energy_change.
bool passes(const cl::lab06::Problem& problem, const cl::lab12::Adjacency& adjacency, const Eigen::Matrix3Xd& x,
            const Eigen::Matrix3Xd& y, int p, const Direction& direction, double alpha) {
  return cl::lab12::vertex_energy_change(problem, adjacency, x, y, p, alpha * direction.d) <=
         -cl::lab12::kSufficientDecrease * alpha * direction.slope;
}

}  // namespace

TEST_CASE("the vertex update is the Newton step times the first of 1 and 1/2 and 1/4 ... that lowers E_i enough",
          "[lab12][pts=1]") {
  // Rest lengths 0.2 to 5 times the length and light particles at Δt = 0.1 s:
  // many full steps overshoot here and are halved, the others are kept whole.
  std::mt19937_64 rng(1212);
  int halved = 0, whole = 0;
  for (int trial = 0; trial < 12; ++trial) {
    cl::Particles start = lab12_test::random_particles(rng, 8);
    start.inv_mass *= 30.0;
    start.inv_mass[trial % 8] = 0.0;
    const std::vector<cl::Spring> springs = lab12_test::random_springs(rng, start.x, 8, 0.2, 5.0, 0.0, 3.0);
    const double dt = 0.1;
    const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, springs, dt);
    const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(8, springs);
    const Eigen::Matrix3Xd y = cl::lab06::predict(start, Eigen::Vector3d(0.0, -9.81, 0.0), dt);
    const Eigen::Matrix3Xd& x = start.x;
    CAPTURE(trial, start.x, start.v, start.inv_mass.transpose());
    for (int p = 0; p < 8; ++p) {
      const Eigen::Vector3d update = cl::lab12::vertex_update(problem, adjacency, x, y, p);
      const Direction direction = newton_direction(problem, x, y, p);
      CAPTURE(p, direction.d.transpose(), update.transpose());
      if (!(start.inv_mass[p] > 0.0)) {
        REQUIRE(update == Eigen::Vector3d::Zero());  // pinned
        continue;
      }
      // The expected α: the first power of two that passes, by the test's own direction.
      double alpha = 1.0;
      int halvings = 0;
      while (halvings < cl::lab12::kMaxHalvings && !passes(problem, adjacency, x, y, p, direction, alpha)) {
        alpha *= 0.5, ++halvings;
      }
      CAPTURE(alpha);
      REQUIRE(passes(problem, adjacency, x, y, p, direction, alpha));
      REQUIRE(cl::test::near(update, Eigen::Vector3d(alpha * direction.d), 1e-9 * alpha * direction.d.norm()));
      (halvings ? halved : whole) += 1;
    }
  }
  CAPTURE(halved, whole);
  REQUIRE(halved > 0);  // the scenes do exercise the backtracking ...
  REQUIRE(whole > 0);   // ... and the full step
}

TEST_CASE("g never increases over one vertex update: compressed springs and the three-particle scene",
          "[lab12][pts=1]") {
  // The three particles: the full step of vertex 1 raises g (scenes.h).
  {
    const lab12_test::ThreeParticles scene = lab12_test::three_particles();
    const cl::lab06::Problem problem = cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
    const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(3, scene.springs);
    const Eigen::Matrix3Xd y = cl::lab06::predict(scene.particles, scene.gravity, scene.dt);
    Eigen::Matrix3Xd x = scene.particles.x;
    const double start = cl::lab06::objective(problem, x, y);
    for (int round = 0; round < 20; ++round) {
      for (const int p : {0, 2, 1}) {  // the colour order
        const double before = cl::lab06::objective(problem, x, y);
        x.col(p) += cl::lab12::vertex_update(problem, adjacency, x, y, p);
        const double after = cl::lab06::objective(problem, x, y);
        CAPTURE(round, p, before, after, x);
        REQUIRE(cl::test::at_most("g after the update", after, before + 1e-13 * std::abs(before)));
      }
    }
    // And it does go down: a no-op everywhere would pass the loop above.
    REQUIRE(cl::test::at_most("g after 20 rounds", cl::lab06::objective(problem, x, y), 0.9 * start));
  }
  // Rest lengths up to 3 times the current length and light particles: the
  // unclamped block is indefinite here, and a full step can climb.
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
        x.col(p) += cl::lab12::vertex_update(problem, adjacency, x, y, p);
        const double after = cl::lab06::objective(problem, x, y);
        CAPTURE(trial, round, p, before, after);
        REQUIRE(cl::test::at_most("g after the update", after, before + 1e-13 * std::abs(before)));
        if (!(start.inv_mass[p] > 0.0)) REQUIRE(x.col(p) == held);
      }
    }
  }
}
