// Graded tests for lab07.3 and lab07.4: one linear spring in 1-D, where the
// step has a closed form. A pinned particle at the origin, a bead of mass m at
// x = ℓ > 0 on the x axis, rest length L, stiffness k, no gravity. Then
// φ = ℓ − L, J = [1 0 0], C = 1/k, and the KKT system reduces to
//     m v_new − Δt λ = m v,   Δt v_new + λ/k = −φ
// so v_new = (m v − Δt k φ)/(m + Δt² k) and λ = −k(φ + Δt v_new).
// solve_kkt gets the system as the test writes it out (not kkt_system's), and
// neither case runs update_positions: each solve is charged to its own task.
#include <cmath>
#include <string>

#include "tests/support/catch.h"

#include "constrained.h"
#include "scenes_for_tests.h"
#include "step.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

namespace {

template <typename Solve>
void check_spring(Solve solve) {
  for (const double k : {1e-3, 1.0, 250.0, 1e6}) {
    for (const double m : {0.01, 1.0, 300.0}) {
      for (const double dt : {1e-3, 1.0 / 60.0, 0.5}) {
        const double length = 1.7, rest = 1.2, v = -0.8;
        cl::Particles particles;
        particles.x.resize(3, 2);
        particles.x.col(0).setZero();
        particles.x.col(1) = Vector3d(length, 0.0, 0.0);
        particles.v.setZero(3, 2);
        particles.v(0, 1) = v;
        particles.inv_mass.resize(2);
        particles.inv_mass << 0.0, 1.0 / m;
        cl::lab07::StepSettings settings;
        settings.dt = dt;
        settings.gravity.setZero();
        const double phi = length - rest;
        const double v_new = (m * v - dt * k * phi) / (m + dt * dt * k);
        const double lambda = -k * (phi + dt * v_new);
        CAPTURE(k, m, dt, v_new, lambda);
        const std::vector<cl::Spring> springs{cl::Spring{0, 1, rest, k}};
        const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
        const cl::lab07::LinearizedStep step = cl::lab07::linearize(particles, springs, map, settings);
        const cl::lab07::StepSolution result = solve(step);
        REQUIRE(cl::test::solved(result));
        REQUIRE(result.velocity.size() == 3);
        REQUIRE(result.lambda.size() == 1);
        CHECK(cl::test::near(result.velocity, Vector3d(v_new, 0.0, 0.0), 1e-10 * std::abs(v_new), "v_new"));
        CHECK(cl::test::near(result.lambda[0], lambda, std::max(1e-9 * std::abs(lambda), 1e-12 * k * length), "lambda"));
      }
    }
  }
}

}  // namespace

TEST_CASE("solve_kkt steps a 1-D linear spring to v_new = (m v - dt k phi)/(m + dt^2 k)", "[lab07][pts=1]") {
  check_spring([](const cl::lab07::LinearizedStep& step) {
    return cl::lab07::solve_kkt(lab07_test::sparse_kkt(step), step.velocity.size());
  });
}

TEST_CASE("the Schur solve steps a 1-D linear spring to v_new = (m v - dt k phi)/(m + dt^2 k)", "[lab07][pts=1]") {
  check_spring([](const cl::lab07::LinearizedStep& step) { return cl::lab07::solve_schur(step); });
}
