// Graded tests for lab13.2: the re-based velocity. At the step's start it is
// the particles' own velocity, so the first Newton iteration is lab 09's
// stable step; at any iterate x_k, lab 09's system with it is the Newton
// system of README.md, solved here densely.
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/LU>
#include "tests/support/catch.h"

#include "../lab06_projective_dynamics/simulation.h"
#include "constrained_newton.h"
#include "lab13_scenes.h"
#include "stable_step.h"
#include "step.h"
#include "tests/support/checks.h"

using cl::test::near;

TEST_CASE("rebased velocity at the start of the step is the velocity", "[lab13][pts=1]") {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const lab13_test::RandomScene scene = lab13_test::random_scene(rng, 5, 2, 1, 100.0);
    CAPTURE(scene.text);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const Eigen::Vector3d gravity(0.3, -9.81, 1.0);
    const double dt = 0.01 * static_cast<double>(seed);
    const Eigen::Matrix3Xd y = cl::lab06::predict(scene.particles, gravity, dt);
    const Eigen::VectorXd v = cl::lab13::rebased_velocity(scene.particles.x, y, map, gravity, dt);
    const Eigen::VectorXd expected = cl::gather_stacked(scene.particles.v, map);
    CHECK(near(v, expected, 1e-12, "unknown entry"));
  }
}

TEST_CASE("one iteration from x is lab 09's stable step with the same K_g", "[lab13][pts=3]") {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const bool hard = seed % 3 == 0;
    const lab13_test::RandomScene scene =
        lab13_test::random_scene(rng, 4 + static_cast<int>(seed % 4), 1, hard ? 0 : 2, hard ? INFINITY : 1e4);
    CAPTURE(hard, scene.text);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    cl::lab09::StableSettings stable;
    stable.step.dt = 0.02;
    stable.step.gravity = Eigen::Vector3d(0.0, -9.81, 0.0);
    stable.step.method = hard ? cl::lab07::Method::kKkt : cl::lab07::Method::kSchur;
    const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
    std::uniform_real_distribution<double> tension(-5.0, 0.0);
    Eigen::VectorXd lambda(m);
    for (Eigen::Index e = 0; e < m; ++e) lambda[e] = tension(rng);
    // Lab 09's step with λ̄ = lambda.
    cl::Particles expected = scene.particles;
    const cl::lab09::StableStepResult step = cl::lab09::stable_step(expected, scene.springs, map, stable, lambda);
    REQUIRE(cl::test::healthy(step));
    // Lab 13's first iteration: lab 09's solve at x_old with the re-based velocity.
    const Eigen::Matrix3Xd y = cl::lab06::predict(scene.particles, stable.step.gravity, stable.step.dt);
    cl::lab07::LinearizedStep linear = cl::lab07::linearize(scene.particles, scene.springs, map, stable.step);
    linear.velocity = cl::lab13::rebased_velocity(scene.particles.x, y, map, stable.step.gravity, stable.step.dt);
    const cl::SparseMatrix stiffness =
        cl::lab09::geometric_stiffness(scene.particles.x, scene.springs, lambda, map, stable.compression);
    const cl::lab07::StepSolution solution = cl::lab09::solve_stiff(linear, stiffness, stable.step.method);
    REQUIRE(cl::test::solved(solution));
    Eigen::Matrix3Xd x = scene.particles.x;
    for (int u = 0; u < map.unknowns(); ++u) {
      x.col(map.particle_of[static_cast<std::size_t>(u)]) += stable.step.dt * solution.velocity.segment<3>(3 * u);
    }
    CHECK(near(x, expected.x, 1e-10, "particle"));
    CHECK(near(solution.lambda, step.lambda, 1e-10 * (1.0 + step.lambda.cwiseAbs().maxCoeff()), "spring"));
  }
}

TEST_CASE("lab 09's system with the rebased velocity is the Newton system at any iterate", "[lab13][pts=2]") {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const lab13_test::RandomScene scene = lab13_test::random_scene(rng, 4 + static_cast<int>(seed % 3), 1, 1, 1e3);
    CAPTURE(scene.text);
    const cl::Particles& p = scene.particles;
    const cl::MovableMap map = cl::make_movable_map(p.inv_mass);
    const double dt = 0.02;
    const Eigen::Vector3d gravity(0.0, -9.81, 2.0);
    const Eigen::Matrix3Xd y = cl::lab06::predict(p, gravity, dt);
    // An iterate away from x_old and from y.
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    cl::Particles at = p;
    for (int u = 0; u < map.unknowns(); ++u) {
      at.x.col(map.particle_of[static_cast<std::size_t>(u)]) += 0.05 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    }
    const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
    Eigen::VectorXd lambda(m);
    for (Eigen::Index e = 0; e < m; ++e) lambda[e] = -3.0 + unit(rng);
    cl::lab07::StepSettings settings;
    settings.dt = dt;
    settings.gravity = gravity;
    cl::lab07::LinearizedStep linear = cl::lab07::linearize(at, scene.springs, map, settings);
    linear.velocity = cl::lab13::rebased_velocity(at.x, y, map, gravity, dt);
    const cl::SparseMatrix stiffness =
        cl::lab09::geometric_stiffness(at.x, scene.springs, lambda, map, cl::lab09::Compression::kKeep);
    const cl::lab07::StepSolution solution = cl::lab09::solve_stiff(linear, stiffness, cl::lab07::Method::kKkt);
    REQUIRE(cl::test::solved(solution));
    // [M/Δt² − K_g, −Jᵀ; J, C] [Δx; λ] = [M(y − x_k)/Δt²; −φ], dense.
    const Eigen::Index n3 = 3 * map.unknowns();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n3 + m, n3 + m);
    Eigen::VectorXd b(n3 + m);
    const Eigen::MatrixXd jacobian(linear.jacobian);
    for (Eigen::Index k = 0; k < n3; ++k) {
      const int particle = map.particle_of[static_cast<std::size_t>(k / 3)];
      const double mass = 1.0 / p.inv_mass[particle];
      a(k, k) = mass / (dt * dt);
      b[k] = mass * (y(k % 3, particle) - at.x(k % 3, particle)) / (dt * dt);
    }
    a.topLeftCorner(n3, n3) -= Eigen::MatrixXd(stiffness);
    a.topRightCorner(n3, m) = -jacobian.transpose();
    a.bottomLeftCorner(m, n3) = jacobian;
    for (Eigen::Index e = 0; e < m; ++e) {
      a(n3 + e, n3 + e) = 1.0 / scene.springs[static_cast<std::size_t>(e)].stiffness;
      b[n3 + e] = -linear.phi[e];
    }
    const Eigen::VectorXd z = a.fullPivLu().solve(b);
    CHECK(near(Eigen::VectorXd(dt * solution.velocity), Eigen::VectorXd(z.head(n3)), 1e-9, "dx"));
    CHECK(near(solution.lambda, Eigen::VectorXd(z.tail(m)), 1e-7 * (1.0 + z.tail(m).cwiseAbs().maxCoeff()),
               "lambda_new"));
  }
}

TEST_CASE("rebased velocity refuses mismatched sizes and a bad dt", "[lab13][pts=1]") {
  std::mt19937_64 rng(5);
  const lab13_test::RandomScene scene = lab13_test::random_scene(rng, 4, 1, 0, 10.0);
  const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
  const Eigen::Vector3d g(0.0, -9.81, 0.0);
  const Eigen::Matrix3Xd& x = scene.particles.x;
  CHECK_THROWS_AS(cl::lab13::rebased_velocity(x, x.leftCols(2), map, g, 0.01), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::rebased_velocity(x, x, map, g, -1.0), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab13::rebased_velocity(x, x, cl::make_movable_map(Eigen::VectorXd::Ones(2)), g, 0.01),
                  std::invalid_argument);
}
