// Graded tests for lab08.2, xpbd_step: the step's structure (λ reset once per
// step, accumulated over the sweeps), lab 04's PBD step at zero compliance,
// invalid settings.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "pbd.h"
#include "tests/support/checks.h"
#include "xpbd.h"

using cl::lab04::ConstraintSet;
using cl::lab08::XpbdSettings;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

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

}  // namespace

TEST_CASE("one XPBD step is prediction then a lambda reset then K sweeps then the velocity update",
          "[lab08][pts=2]") {
  // The step written out with the formulas of xpbd.h (not with the student's
  // projection), for springs of mixed stiffness, one particle pinned, a
  // shuffled order; `lambda` comes in holding garbage from "an earlier step",
  // which must not leak into this one.
  std::mt19937_64 rng(83);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> stretch(0.5, 1.5);
  for (int trial = 0; trial < 12; ++trial) {
    cl::Particles particles = random_particles(rng, 7);
    particles.inv_mass[3] = 0.0;
    std::vector<cl::Spring> springs;
    for (int i = 0; i < 7; ++i) {
      for (int j = i + 1; j < 7; j += 2) {
        const double stiffness = (i + j) % 4 == 0 ? cl::kInfiniteStiffness : std::pow(10.0, 1.0 + 3.0 * unit(rng));
        springs.push_back({i, j, stretch(rng) * (particles.x.col(i) - particles.x.col(j)).norm(), stiffness});
      }
    }
    ConstraintSet constraints = cl::lab04::make_constraint_set(7, springs);
    std::shuffle(constraints.order.begin(), constraints.order.end(), rng);
    XpbdSettings settings;
    settings.dt = 0.01 + 0.02 * trial;
    settings.gravity = Vector3d(0.2, -9.81, -0.4);
    settings.iterations = trial % 4 == 0 ? 0 : trial % 5 + 1;
    CAPTURE(trial, settings.dt, settings.iterations, particles.x, particles.v, particles.inv_mass.transpose(),
            constraints.order);

    Matrix3Xd v = particles.v;
    Matrix3Xd p = particles.x;
    for (Eigen::Index i = 0; i < 7; ++i) {
      if (particles.inv_mass[i] > 0.0) {
        v.col(i) += settings.dt * settings.gravity;
        p.col(i) += settings.dt * v.col(i);
      }
    }
    VectorXd expected_lambda = VectorXd::Zero(static_cast<Eigen::Index>(springs.size()));
    for (int k = 0; k < settings.iterations; ++k) {
      for (const int s : constraints.order) {
        const cl::Spring& spring = springs[static_cast<std::size_t>(s)];
        const double w_i = particles.inv_mass[spring.i], w_j = particles.inv_mass[spring.j];
        const double alpha_tilde =
            std::isinf(spring.stiffness) ? 0.0 : 1.0 / (spring.stiffness * settings.dt * settings.dt);
        const Vector3d d = p.col(spring.i) - p.col(spring.j);
        const double dlambda =
            (-(d.norm() - spring.rest_length) - alpha_tilde * expected_lambda[s]) / (w_i + w_j + alpha_tilde);
        const Vector3d n = d / d.norm();
        p.col(spring.i) += w_i * dlambda * n;
        p.col(spring.j) -= w_j * dlambda * n;
        expected_lambda[s] += dlambda;
      }
    }
    const Matrix3Xd expected_v = (p - particles.x) / settings.dt;

    cl::Particles stepped = particles;
    VectorXd lambda = VectorXd::Constant(static_cast<Eigen::Index>(springs.size()), 1e3);
    cl::lab08::xpbd_step(stepped, constraints, settings, lambda);
    REQUIRE(lambda.size() == expected_lambda.size());
    CAPTURE(lambda.transpose(), expected_lambda.transpose());
    REQUIRE(cl::test::near(stepped.x, p, 1e-12));
    REQUIRE(cl::test::near(stepped.v, expected_v, 1e-12 / settings.dt));
    REQUIRE(cl::test::near(lambda, expected_lambda, 1e-12 * (1.0 + expected_lambda.cwiseAbs().maxCoeff())));
    REQUIRE(cl::test::near(stepped.inv_mass, particles.inv_mass, 0.0));
  }
}

TEST_CASE("with zero compliance the XPBD step is lab 04's Gauss-Seidel PBD step", "[lab08][pts=2]") {
  // α = 0 for every spring ("inf" stiffness): α̃ = 0, and each projection is
  // lab 01's, so the step is lab 04's pbd_step with Gauss-Seidel sweeps in the
  // same order. Compared step by step from the same state (a hanging cloth
  // with random velocities), to round-off.
  std::mt19937_64 rng(89);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double dt : {1e-3, 1.0 / 60.0, 0.5}) {
    for (const int iterations : {1, 4, 20}) {
      cl::Scene scene = cl::parse_scene(
          R"({"cloth": {"nx": 7, "ny": 6, "pin": ["top-left", "top-right"], "springs": ["structural", "shear", "bending"]}})",
          "test-cloth");
      for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
        scene.particles.v.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
        if (scene.particles.inv_mass[p] > 0.0) scene.particles.inv_mass[p] *= std::pow(4.0, unit(rng));
      }
      ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
      std::shuffle(constraints.order.begin(), constraints.order.end(), rng);
      cl::lab04::PbdSettings pbd;
      pbd.dt = dt;
      pbd.iterations = iterations;
      pbd.projection = cl::lab04::Projection::kGaussSeidel;
      XpbdSettings xpbd;
      xpbd.dt = dt;
      xpbd.iterations = iterations;
      CAPTURE(dt, iterations);
      cl::Particles state = scene.particles;
      for (int step = 1; step <= 20; ++step) {
        cl::Particles by_xpbd = state;
        VectorXd lambda;
        cl::lab08::xpbd_step(by_xpbd, constraints, xpbd, lambda);
        cl::lab04::pbd_step(state, constraints, pbd);
        const double scale = state.x.cwiseAbs().maxCoeff() + dt * state.v.cwiseAbs().maxCoeff();
        CAPTURE(step, scale);
        REQUIRE(cl::test::near(by_xpbd.x, state.x, 1e-12 * scale));
        REQUIRE(cl::test::near(by_xpbd.v, state.v, 1e-12 * scale / dt));
        REQUIRE(lambda.size() == static_cast<Eigen::Index>(scene.springs.size()));
      }
    }
  }
}

TEST_CASE("invalid XPBD settings throw std::invalid_argument and change nothing", "[lab08][pts=1]") {
  cl::Particles particles;
  particles.x = Matrix3Xd::Zero(3, 2);
  particles.x(0, 1) = 1.0;
  particles.v = Matrix3Xd::Zero(3, 2);
  particles.inv_mass = VectorXd::Ones(2);
  const cl::Particles start = particles;
  const ConstraintSet constraints = cl::lab04::make_constraint_set(2, {cl::Spring{0, 1, 1.0, 50.0}});
  VectorXd lambda = VectorXd::Constant(1, 7.0);  // an earlier step's λ: a throw must leave it
  const VectorXd start_lambda = lambda;
  auto unchanged = [&] {
    return particles.x == start.x && particles.v == start.v && lambda.size() == 1 && lambda == start_lambda;
  };
  for (const double dt : {0.0, -0.01, std::numeric_limits<double>::quiet_NaN(),
                          std::numeric_limits<double>::infinity()}) {
    CAPTURE(dt);
    XpbdSettings settings;
    settings.dt = dt;
    REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, constraints, settings, lambda), std::invalid_argument);
    REQUIRE(unchanged());
  }
  XpbdSettings settings;
  settings.iterations = -1;
  REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, constraints, settings, lambda), std::invalid_argument);
  settings.iterations = 3;
  for (const double stiffness : {0.0, -5.0, std::numeric_limits<double>::quiet_NaN()}) {
    CAPTURE(stiffness);
    const ConstraintSet bad = cl::lab04::make_constraint_set(2, {cl::Spring{0, 1, 1.0, stiffness}});
    REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, bad, settings, lambda), std::invalid_argument);
    REQUIRE(unchanged());
  }
  ConstraintSet bad_order = constraints;
  bad_order.order = {0, 1};
  REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, bad_order, settings, lambda), std::invalid_argument);
  ConstraintSet bad_index = constraints;
  bad_index.springs[0].j = 2;
  REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, bad_index, settings, lambda), std::invalid_argument);
  cl::Particles wrong_size = particles;
  wrong_size.inv_mass = VectorXd::Ones(3);
  REQUIRE_THROWS_AS(cl::lab08::xpbd_step(wrong_size, constraints, settings, lambda), std::invalid_argument);
  REQUIRE(unchanged());
  // What the projection would reject is checked before the first sweep: the
  // particles and λ stay as they were (not half a sweep later).
  for (const double inv_mass : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    CAPTURE(inv_mass);
    particles.inv_mass[1] = inv_mass;
    const cl::Particles bad_start = particles;
    REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, constraints, settings, lambda), std::invalid_argument);
    REQUIRE((particles.x == bad_start.x && particles.v == bad_start.v && lambda == start_lambda));
    particles.inv_mass[1] = 1.0;
  }
  for (const double rest : {-0.5, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    CAPTURE(rest);
    const ConstraintSet bad = cl::lab04::make_constraint_set(2, {cl::Spring{0, 1, rest, 50.0}});
    REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, bad, settings, lambda), std::invalid_argument);
    REQUIRE(unchanged());
  }
  XpbdSettings tiny = settings;  // α̃ = (1/50) / dt² overflows
  tiny.dt = 1e-160;
  REQUIRE_THROWS_AS(cl::lab08::xpbd_step(particles, constraints, tiny, lambda), std::invalid_argument);
  REQUIRE(unchanged());
  settings.iterations = 0;
  REQUIRE_NOTHROW(cl::lab08::xpbd_step(particles, constraints, settings, lambda));
}
