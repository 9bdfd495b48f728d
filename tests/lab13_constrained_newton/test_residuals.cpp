// Graded tests for lab13.1: the residuals r_x = M(x − y)/Δt² − Jᵀλ and
// r_λ = φ + Cλ, against a per-spring loop written out here, and their zero at
// a hanging bead's rest state (a closed form).
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "tests/support/catch.h"

#include "constrained_newton.h"
#include "lab13_scenes.h"
#include "tests/support/checks.h"

using cl::test::near;

TEST_CASE("residuals are the inertia minus J transpose lambda and phi plus C lambda", "[lab13][pts=3]") {
  const double inf = std::numeric_limits<double>::infinity();
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const int kind = static_cast<int>(seed % 3);  // 0 compliant, 1 mixed, 2 all hard
    lab13_test::RandomScene scene = lab13_test::random_scene(rng, 3 + static_cast<int>(seed % 5), 1, 2, 1.0);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t e = 0; e < scene.springs.size(); ++e) {
      scene.springs[e].stiffness = kind == 2 || (kind == 1 && e % 2 == 0) ? inf : std::pow(10.0, 3.0 * unit(rng) + 3.0);
    }
    CAPTURE(kind, scene.text);
    const cl::Particles& p = scene.particles;
    const cl::MovableMap map = cl::make_movable_map(p.inv_mass);
    const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
    Eigen::Matrix3Xd y = p.x;
    for (Eigen::Index i = 0; i < y.cols(); ++i) {
      if (p.inv_mass[i] > 0.0) y.col(i) += 0.1 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    }
    Eigen::VectorXd lambda(m), compliance(m);
    for (Eigen::Index e = 0; e < m; ++e) {
      lambda[e] = 10.0 * unit(rng);
      const double k = scene.springs[static_cast<std::size_t>(e)].stiffness;
      compliance[e] = std::isfinite(k) ? 1.0 / k : 0.0;
    }
    if (kind == 2) compliance.resize(0);  // lab 07's convention: no compliance block at all
    const double dt = 0.02;
    const cl::lab13::Residuals r =
        cl::lab13::residuals(p.x, y, lambda, scene.springs, p.inv_mass, map, compliance, dt);
    // Written out per particle and per spring.
    Eigen::Matrix3Xd inertia = Eigen::Matrix3Xd::Zero(3, p.x.cols());
    Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, p.x.cols());
    Eigen::VectorXd constraint(m);
    for (Eigen::Index i = 0; i < p.x.cols(); ++i) {
      if (p.inv_mass[i] > 0.0) inertia.col(i) = (p.x.col(i) - y.col(i)) / (p.inv_mass[i] * dt * dt);
    }
    for (Eigen::Index e = 0; e < m; ++e) {
      const cl::Spring& s = scene.springs[static_cast<std::size_t>(e)];
      const Eigen::Vector3d d = p.x.col(s.i) - p.x.col(s.j);
      const Eigen::Vector3d n = d / d.norm();
      force.col(s.i) += lambda[e] * n;
      force.col(s.j) -= lambda[e] * n;
      const double c = compliance.size() == 0 ? 0.0 : compliance[e];
      constraint[e] = d.norm() - s.rest_length + c * lambda[e];
    }
    REQUIRE(r.inertia.size() == 3 * map.unknowns());
    REQUIRE(r.constraint_force.size() == 3 * map.unknowns());
    REQUIRE(r.force.size() == 3 * map.unknowns());
    REQUIRE(r.constraint.size() == m);
    const Eigen::VectorXd expected_inertia = cl::gather_stacked(inertia, map);
    const Eigen::VectorXd expected_force = cl::gather_stacked(force, map);
    CHECK(near(r.inertia, expected_inertia, 1e-9 * (1.0 + expected_inertia.cwiseAbs().maxCoeff()), "inertia"));
    CHECK(near(r.constraint_force, expected_force, 1e-12 * (1.0 + expected_force.cwiseAbs().maxCoeff()),
               "J^T lambda"));
    const Eigen::VectorXd expected_r = expected_inertia - expected_force;
    CHECK(near(r.force, expected_r, 1e-9 * (1.0 + expected_r.cwiseAbs().maxCoeff()), "r_x"));
    CHECK(near(r.constraint, constraint, 1e-13, "r_lambda (spring)"));
  }
}

TEST_CASE("residuals vanish at a hanging bead at rest", "[lab13][pts=1]") {
  // A bead of mass m on a spring of stiffness k below a pin, at rest, stretched
  // by m g / k: with λ = −m g (tension) both residuals are 0 for y = x + Δt² g.
  for (const double k : {10.0, 1e4, 1e8, std::numeric_limits<double>::infinity()}) {
    CAPTURE(k);
    const double mass = 0.3, g = 9.81, rest = 0.5, dt = 0.01;
    const double stretch = std::isfinite(k) ? mass * g / k : 0.0;
    Eigen::Matrix3Xd x(3, 2);
    x << 0.0, 0.0, 0.0, -(rest + stretch), 0.0, 0.0;
    Eigen::VectorXd inv_mass(2);
    inv_mass << 0.0, 1.0 / mass;
    Eigen::Matrix3Xd y = x;
    y(1, 1) -= dt * dt * g;
    const std::vector<cl::Spring> springs{{0, 1, rest, k}};
    const cl::MovableMap map = cl::make_movable_map(inv_mass);
    Eigen::VectorXd compliance(1);
    compliance << (std::isfinite(k) ? 1.0 / k : 0.0);
    Eigen::VectorXd lambda(1);
    lambda << -mass * g;
    const cl::lab13::Residuals r = cl::lab13::residuals(x, y, lambda, springs, inv_mass, map, compliance, dt);
    REQUIRE(r.force.size() == 3);
    REQUIRE(r.constraint.size() == 1);
    CHECK(near(r.force, Eigen::Vector3d::Zero(), 1e-12, "r_x"));
    CHECK(near(r.constraint[0], 0.0, 1e-15, "r_lambda"));
    CHECK(near(r.inertia[1], mass * g, 1e-12, "inertia y: M(x - y)/dt^2 = m g, the weight the spring holds"));
  }
}

TEST_CASE("residuals refuse input of the wrong size and a bad dt", "[lab13][pts=1]") {
  std::mt19937_64 rng(3);
  const lab13_test::RandomScene scene = lab13_test::random_scene(rng, 4, 1, 1, 100.0);
  const cl::Particles& p = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(p.inv_mass);
  const Eigen::Index m = static_cast<Eigen::Index>(scene.springs.size());
  const Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  const Eigen::VectorXd compliance = Eigen::VectorXd::Constant(m, 0.01);
  using cl::lab13::residuals;
  CHECK_THROWS_AS(residuals(p.x, p.x, Eigen::VectorXd::Zero(m + 1), scene.springs, p.inv_mass, map, compliance, 0.01),
                  std::invalid_argument);
  CHECK_THROWS_AS(residuals(p.x, p.x.leftCols(3), lambda, scene.springs, p.inv_mass, map, compliance, 0.01),
                  std::invalid_argument);
  CHECK_THROWS_AS(residuals(p.x, p.x, lambda, scene.springs, p.inv_mass, map, compliance.head(m - 1), 0.01),
                  std::invalid_argument);
  CHECK_THROWS_AS(residuals(p.x, p.x, lambda, scene.springs, p.inv_mass.head(3), map, compliance, 0.01),
                  std::invalid_argument);
  CHECK_THROWS_AS(residuals(p.x, p.x, lambda, scene.springs, p.inv_mass, map, compliance, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(residuals(p.x, p.x, lambda, scene.springs, p.inv_mass, map, compliance, std::nan("")),
                  std::invalid_argument);
}
