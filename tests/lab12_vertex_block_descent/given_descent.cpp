// Ungraded tests of lab 12's given code ([lab12_given], run on the reference
// by ctest -L unit): the adjacency, the colour groups, the adaptive initial
// guess, and the Chebyshev loop around the sweep.
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "descent.h"
#include "scenes.h"
#include "tests/support/checks.h"

TEST_CASE("the adjacency lists each spring at both ends in increasing order; groups skip pinned particles",
          "[lab12_given]") {
  const std::vector<cl::Spring> springs{{2, 0, 1.0, 1.0}, {0, 1, 1.0, 1.0}, {1, 2, 1.0, 1.0}, {3, 1, 1.0, 1.0}};
  const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(4, springs);
  REQUIRE(adjacency.offsets == std::vector<int>{0, 2, 5, 7, 8});
  REQUIRE(adjacency.springs == std::vector<int>{0, 1, 1, 2, 3, 0, 2, 3});
  Eigen::VectorXd inv_mass(4);
  inv_mass << 1.0, 0.0, 1.0, 1.0;
  // Colours 0 1 2 0: colour 1 holds only the pinned particle and is left out.
  REQUIRE(cl::lab12::colour_groups({0, 1, 2, 0}, inv_mass) == std::vector<std::vector<int>>{{0, 3}, {2}});
  REQUIRE_THROWS_AS(cl::lab12::make_adjacency(2, {{0, 2, 1.0, 1.0}}), std::invalid_argument);
}

TEST_CASE("the adaptive guess is x + dt v + dt^2 a g-hat with a clamped to [0, |g|]", "[lab12_given]") {
  const Eigen::Vector3d gravity(0.0, -9.81, 3.0);
  const double g = gravity.norm(), dt = 0.02;
  const Eigen::Vector3d down = gravity / g;
  cl::Particles particles;
  particles.x = Eigen::Matrix3Xd::Random(3, 5);
  particles.v = Eigen::Matrix3Xd::Random(3, 5);
  particles.inv_mass = Eigen::VectorXd::Ones(5);
  particles.inv_mass[4] = 0.0;
  Eigen::Matrix3Xd previous = particles.v;
  previous.col(1) -= dt * gravity;         // a = g: the full fall, y
  previous.col(2) -= 0.5 * dt * gravity;   // a = g/2
  previous.col(3) += 2.0 * dt * gravity;   // a = −2g: clamped to 0
  previous.col(4) -= dt * gravity;         // pinned: stays
  const Eigen::Matrix3Xd x = cl::lab12::adaptive_guess(particles, previous, true, gravity, dt);
  const Eigen::Matrix3Xd y = cl::lab06::predict(particles, gravity, dt);
  REQUIRE(cl::test::near(x.col(0), Eigen::Vector3d(particles.x.col(0) + dt * particles.v.col(0)), 1e-15));
  REQUIRE(cl::test::near(x.col(1), Eigen::Vector3d(y.col(1)), 1e-14));
  REQUIRE(cl::test::near(x.col(2), Eigen::Vector3d(particles.x.col(2) + dt * particles.v.col(2) + 0.5 * dt * dt * g * down),
                         1e-14));
  REQUIRE(cl::test::near(x.col(3), Eigen::Vector3d(particles.x.col(3) + dt * particles.v.col(3)), 1e-15));
  REQUIRE(x.col(4) == particles.x.col(4));
  REQUIRE(cl::lab12::adaptive_guess(particles, previous, false, gravity, dt) == y);  // no previous step: y
}

TEST_CASE("rho = 0 is plain VBD bit for bit, and Chebyshev never raises g over an iteration", "[lab12_given]") {
  std::mt19937_64 rng(1211);
  cl::Particles start = lab12_test::random_particles(rng, 20);
  start.inv_mass[0] = 0.0;
  const std::vector<cl::Spring> springs = lab12_test::random_springs(rng, start.x, 25, 0.7, 1.4, 2.0, 4.0);
  const cl::lab12::Solver solver(start.inv_mass, springs, 1.0 / 60.0);
  const Eigen::Matrix3Xd y = cl::lab06::predict(start, Eigen::Vector3d(0.0, -9.81, 0.0), 1.0 / 60.0);
  cl::lab12::Settings settings;
  settings.iterations = 40;
  Eigen::Matrix3Xd plain = y, zero = y;
  solver.minimise(plain, y, cl::lab12::Method::kVbd, settings);
  solver.minimise(zero, y, cl::lab12::Method::kVbdChebyshev, settings);
  REQUIRE(plain == zero);
  settings.rho = 0.99;  // too high: restarts
  Eigen::Matrix3Xd accelerated = y;
  double previous = cl::lab06::objective(solver.problem(), y, y);
  const cl::lab12::StepReport report =
      solver.minimise(accelerated, y, cl::lab12::Method::kVbdChebyshev, settings, [&](const cl::lab12::IterationRecord& r) {
        REQUIRE(cl::test::at_most("g", r.objective, previous + 1e-12 * std::abs(previous)));
        previous = r.objective;
        return false;
      });
  REQUIRE(report.problem.empty());
  REQUIRE(accelerated.col(0) == y.col(0));
}

TEST_CASE("the vertex energy change is g's change, and keeps its first-order term for tiny steps", "[lab12_given]") {
  std::mt19937_64 rng(1214);
  for (int trial = 0; trial < 6; ++trial) {
    cl::Particles start = lab12_test::random_particles(rng, 9);
    start.inv_mass[trial] = 0.0;
    std::vector<cl::Spring> springs = lab12_test::random_springs(rng, start.x, 9, 0.3, 3.0, 0.0, 4.0);
    springs.push_back({7, 8, 0.0, 50.0});  // a zero-rest spring too
    const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, springs, 0.05);
    const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(9, springs);
    const Eigen::Matrix3Xd y = cl::lab06::predict(start, Eigen::Vector3d(0.0, -9.81, 0.0), 0.05);
    const Eigen::Matrix3Xd& x = start.x;
    const double g = cl::lab06::objective(problem, x, y);
    const Eigen::VectorXd gradient = cl::lab06::newton_gradient(problem, x, y);
    CAPTURE(trial);
    for (int p = 0; p < 9; ++p) {
      const Eigen::Vector3d step = 0.3 * Eigen::Vector3d::Random();
      Eigen::Matrix3Xd moved = x;
      moved.col(p) += step;
      CAPTURE(p, step.transpose());
      REQUIRE(cl::test::near(cl::lab12::vertex_energy_change(problem, adjacency, x, y, p, step),
                             cl::lab06::objective(problem, moved, y) - g, 1e-12 * g));
      // A step of 1e-12 m: g's own difference is round-off; the change is its
      // first-order term −f·s to 1e-6 relative.
      const int u = problem.map.unknown_of[static_cast<std::size_t>(p)];
      if (u < 0) continue;
      const Eigen::Vector3d tiny = -1e-12 * gradient.segment<3>(3 * u).normalized();
      const double first_order = gradient.segment<3>(3 * u).dot(tiny);
      REQUIRE(cl::test::near_rel(cl::lab12::vertex_energy_change(problem, adjacency, x, y, p, tiny), first_order, 1e-6));
    }
  }
  cl::Particles start = lab12_test::random_particles(rng, 3);
  const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, {{0, 1, 1.0, 1.0}}, 0.05);
  const cl::lab12::Adjacency adjacency = cl::lab12::make_adjacency(3, problem.springs);
  REQUIRE_THROWS_AS(cl::lab12::vertex_energy_change(problem, adjacency, start.x, start.x, 3, Eigen::Vector3d::Ones()),
                    std::invalid_argument);
}
