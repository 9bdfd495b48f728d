// Graded tests for lab04.1, pbd_step: the closed form without constraints, the
// step's structure, pinned particles, momentum, invalid settings.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "jacobi.h"
#include "pbd.h"
#include "tests/support/checks.h"

using cl::lab04::ConstraintSet;
using cl::lab04::PbdSettings;
using cl::lab04::Projection;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;

namespace {

cl::Particles random_particles(std::mt19937_64& rng, Eigen::Index n) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  cl::Particles particles;
  particles.x.resize(3, n);
  particles.v.resize(3, n);
  particles.inv_mass.resize(n);
  for (Eigen::Index p = 0; p < n; ++p) {
    particles.x.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
    particles.v.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
    particles.inv_mass[p] = std::pow(10.0, unit(rng));
  }
  return particles;
}

// A cloth from the scene generator (row-major grid, structural and shear springs).
cl::Scene cloth_scene(int n, const std::string& pins, const std::string& extra) {
  const std::string text = R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                           R"(, "pin": [)" + pins + "]}" + extra + "}";
  return cl::parse_scene(text, "test-cloth");
}

const char* name_of(Projection projection) {
  return projection == Projection::kGaussSeidel ? "gauss-seidel" : "jacobi";
}

}  // namespace

TEST_CASE("free fall without constraints is symplectic Euler in closed form", "[lab04][pts=2]") {
  // v_{k+1} = v_k + Δt g,  x_{k+1} = x_k + Δt v_{k+1}
  //   =>  x_n = x_0 + nΔt v_0 + Δt² g n(n+1)/2,  v_n = v_0 + nΔt g.
  std::mt19937_64 rng(41);
  const ConstraintSet no_springs = cl::lab04::make_constraint_set(6, {});
  for (const Projection projection : {Projection::kGaussSeidel, Projection::kJacobi}) {
    for (const double dt : {1.0 / 60.0, 1e-3, 0.5}) {
      for (const int iterations : {0, 3}) {
        cl::Particles particles = random_particles(rng, 6);
        const cl::Particles start = particles;
        PbdSettings settings;
        settings.dt = dt;
        settings.gravity = Vector3d(0.3, -9.81, 1.2);
        settings.iterations = iterations;
        settings.projection = projection;
        const int steps = 100;
        CAPTURE(name_of(projection), dt, iterations, steps, start.x, start.v);
        for (int k = 0; k < steps; ++k) cl::lab04::pbd_step(particles, no_springs, settings);
        const double n = steps;
        const Matrix3Xd expected_x =
            (start.x + (n * dt) * start.v).colwise() + (dt * dt * n * (n + 1.0) / 2.0) * settings.gravity;
        const Matrix3Xd expected_v = start.v.colwise() + (n * dt) * settings.gravity;
        // Round-off only: a few ulps of the largest magnitude involved per step.
        const double x_scale = expected_x.cwiseAbs().maxCoeff() + start.x.cwiseAbs().maxCoeff();
        const double v_scale = x_scale / dt;
        REQUIRE(cl::test::near(particles.x, expected_x, 1e-13 * n * x_scale, "particle"));
        REQUIRE(cl::test::near(particles.v, expected_v, 1e-13 * n * v_scale, "particle"));
      }
    }
  }
}

TEST_CASE("one step is gravity then prediction then K sweeps then the velocity update", "[lab04][pts=2]") {
  // Springs away from their rest lengths, one particle pinned, unequal masses.
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> stretch(0.5, 1.5);
  for (int trial = 0; trial < 12; ++trial) {
    cl::Particles particles = random_particles(rng, 7);
    particles.inv_mass[2] = 0.0;
    std::vector<cl::Spring> springs;
    for (int i = 0; i < 7; ++i) {
      for (int j = i + 1; j < 7; j += 2) {
        springs.push_back({i, j, stretch(rng) * (particles.x.col(i) - particles.x.col(j)).norm()});
      }
    }
    ConstraintSet constraints = cl::lab04::make_constraint_set(7, springs);
    std::shuffle(constraints.order.begin(), constraints.order.end(), rng);  // Gauss-Seidel follows `order`
    PbdSettings settings;
    settings.dt = 0.02 + 0.01 * trial;
    settings.gravity = Vector3d(0.0, -9.81, 0.5);
    settings.iterations = trial % 4 == 0 ? 0 : trial % 5 + 1;
    settings.projection = trial % 2 == 0 ? Projection::kGaussSeidel : Projection::kJacobi;
    settings.omega = trial % 3 == 0 ? 0.7 : 1.0;
    CAPTURE(trial, name_of(settings.projection), settings.dt, settings.iterations, settings.omega, particles.x,
            particles.v, particles.inv_mass.transpose(), constraints.order);

    // The step written out with the lab 02 / lab 03 sweeps.
    Matrix3Xd v = particles.v;
    Matrix3Xd p = particles.x;
    for (Eigen::Index i = 0; i < 7; ++i) {
      if (particles.inv_mass[i] > 0.0) {
        v.col(i) += settings.dt * settings.gravity;
        p.col(i) += settings.dt * v.col(i);
      }
    }
    for (int k = 0; k < settings.iterations; ++k) {
      if (settings.projection == Projection::kGaussSeidel) {
        cl::lab02::gauss_seidel_sweep(p, particles.inv_mass, constraints.springs, constraints.order);
      } else {
        Matrix3Xd next;
        cl::lab03::jacobi_sweep(p, next, particles.inv_mass, constraints.springs, constraints.incidence,
                                settings.omega, cl::lab03::Averaging::kByCount);
        p = next;
      }
    }
    const Matrix3Xd expected_v = (p - particles.x) / settings.dt;

    cl::Particles stepped = particles;
    cl::lab04::pbd_step(stepped, constraints, settings);
    REQUIRE(cl::test::near(stepped.x, p, 1e-12, "particle"));
    REQUIRE(cl::test::near(stepped.v, expected_v, 1e-12 / settings.dt, "particle"));
    REQUIRE(cl::test::near(stepped.inv_mass, particles.inv_mass, 0.0, "inv_mass (row: particle)"));
  }
}

TEST_CASE("pinned particles never move and report zero velocity", "[lab04][pts=1]") {
  // Pinned particles with a velocity in the input: they stay put and report v = 0.
  for (const Projection projection : {Projection::kGaussSeidel, Projection::kJacobi}) {
    for (const double dt : {1.0 / 60.0, 0.5}) {
      cl::Scene scene = cloth_scene(9, R"("top-left", "top-right", "bottom-left")", "");
      scene.particles.v.setConstant(0.25);
      const cl::Particles start = scene.particles;
      const ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
      PbdSettings settings;
      settings.dt = dt;
      settings.iterations = 7;
      settings.projection = projection;
      CAPTURE(name_of(projection), dt, settings.iterations);
      int pinned = 0;
      for (int step = 0; step < 60; ++step) {
        cl::lab04::pbd_step(scene.particles, constraints, settings);
        for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
          if (start.inv_mass[p] != 0.0) continue;
          CAPTURE(step);
          const std::string pinned_particle = "pinned particle " + std::to_string(p);
          REQUIRE(cl::test::near(scene.particles.x.col(p), start.x.col(p), 0.0, "x of " + pinned_particle));
          REQUIRE(cl::test::near(scene.particles.v.col(p), Vector3d::Zero(), 0.0, "v of " + pinned_particle));
          ++pinned;
        }
      }
      REQUIRE(pinned == 3 * 60);
      // The free particles did move: the test is not vacuous.
      REQUIRE((scene.particles.x - start.x).cwiseAbs().maxCoeff() > 0.01);
    }
  }
}

TEST_CASE("a free cloth without gravity keeps its total momentum", "[lab04][pts=2]") {
  // Gauss-Seidel projections are internal forces: Σ m Δx = 0 for each one, so
  // with no gravity and nothing pinned Σ m v is constant. Unequal masses,
  // random velocities and a jittered (strained) start make every step work.
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  cl::Scene scene = cloth_scene(8, "", R"(, "gravity": [0, 0, 0], "jitter": {"amplitude": 0.02, "seed": 3})");
  for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
    scene.particles.inv_mass[p] = 64.0 * std::pow(4.0, unit(rng));
    scene.particles.v.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
  }
  const Matrix3Xd start_v = scene.particles.v;
  const Vector3d momentum = cl::linear_momentum(scene.particles);
  const double scale = (scene.particles.v.colwise().norm().array() / scene.particles.inv_mass.transpose().array()).sum();
  const ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  PbdSettings settings;
  settings.gravity = Vector3d::Zero();
  settings.iterations = 10;
  CAPTURE(scene.particles.inv_mass.transpose(), start_v, momentum.transpose(), scale, settings.dt, settings.iterations);
  for (int step = 1; step <= 120; ++step) {
    cl::lab04::pbd_step(scene.particles, constraints, settings);
    CAPTURE(step);
    REQUIRE(cl::test::near((cl::linear_momentum(scene.particles) - momentum).norm(), 0.0, 1e-12 * scale,
                           "‖Σ m v − Σ m v at the start‖"));
  }
  // Not vacuous: the constraints did change the velocities.
  REQUIRE((scene.particles.v - start_v).cwiseAbs().maxCoeff() > 0.1);
}

TEST_CASE("invalid settings throw std::invalid_argument", "[lab04][pts=1]") {
  cl::Particles particles;
  particles.x = Matrix3Xd::Zero(3, 2);
  particles.x(0, 1) = 1.0;
  particles.v = Matrix3Xd::Zero(3, 2);
  particles.inv_mass = Eigen::VectorXd::Ones(2);
  const ConstraintSet constraints = cl::lab04::make_constraint_set(2, {cl::Spring{0, 1, 1.0}});
  for (const double dt : {0.0, -0.01, std::numeric_limits<double>::quiet_NaN(),
                          std::numeric_limits<double>::infinity()}) {
    CAPTURE(dt);
    PbdSettings settings;
    settings.dt = dt;
    REQUIRE_THROWS_AS(cl::lab04::pbd_step(particles, constraints, settings), std::invalid_argument);
  }
  PbdSettings settings;
  settings.iterations = -1;
  REQUIRE_THROWS_AS(cl::lab04::pbd_step(particles, constraints, settings), std::invalid_argument);
  settings.iterations = 0;
  REQUIRE_NOTHROW(cl::lab04::pbd_step(particles, constraints, settings));
}
