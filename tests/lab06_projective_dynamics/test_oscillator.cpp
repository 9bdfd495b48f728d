// Graded test of whole steps: a zero-rest-length spring is linear, so implicit
// Euler has a closed form, and projective dynamics reaches it in one iteration.
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "projective_dynamics.h"
#include "simulation.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

TEST_CASE("a zero-rest-length spring from a pinned point steps as implicit Euler for a linear oscillator",
          "[lab06][pts=2]") {
  // m v' = m v + Δt (m g − k (x' − p)),  x' = x + Δt v'
  //   =>  x' = (x + Δt v + Δt² g + Δt² ω² p) / (1 + Δt² ω²),  ω² = k/m,  v' = (x' − x)/Δt.
  // E = k/2 ‖x − p‖² has the constant Hessian k I: d_e = 0, and the first
  // global step already solves the step exactly.
  std::mt19937_64 rng(66);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double dt : {1e-3, 1.0 / 60.0, 0.5}) {
    for (const int iterations : {1, 7}) {
      for (const cl::lab06::Method method : {cl::lab06::Method::kProjectiveDynamics, cl::lab06::Method::kNewton}) {
        const double mass = std::pow(10.0, 2.0 * unit(rng));
        const double k = std::pow(10.0, 3.0 * unit(rng));
        const Vector3d pin(unit(rng), unit(rng), unit(rng));
        const Vector3d gravity(0.5 * unit(rng), -9.81, 0.0);
        cl::Particles particles;
        particles.x.resize(3, 2);
        particles.v.resize(3, 2);
        particles.x.col(0) = pin;
        particles.x.col(1) = pin + Vector3d(unit(rng), unit(rng), unit(rng));
        particles.v.col(0).setZero();
        particles.v.col(1) = Vector3d(unit(rng), unit(rng), unit(rng));
        particles.inv_mass.resize(2);
        particles.inv_mass << 0.0, 1.0 / mass;
        CAPTURE(dt, iterations, cl::lab06::method_name(method), mass, k, pin.transpose(), gravity.transpose(),
                particles.x.col(1).transpose(), particles.v.col(1).transpose());
        cl::lab06::Solver solver(cl::lab06::make_problem(particles.inv_mass, {{0, 1, 0.0, k}}, dt), method);
        cl::lab06::StepSettings settings;
        settings.gravity = gravity;
        settings.iterations = iterations;

        const double w2dt2 = k / mass * dt * dt;
        Vector3d x = particles.x.col(1), v = particles.v.col(1);
        for (int step = 1; step <= 40; ++step) {
          const Vector3d next = (x + dt * v + dt * dt * gravity + w2dt2 * pin) / (1.0 + w2dt2);
          v = (next - x) / dt;
          x = next;
          const cl::lab06::StepReport report = solver.step(particles, settings);
          CAPTURE(step, report.problem, x.transpose(), particles.x.col(1).transpose());
          REQUIRE(report.problem.empty());
          const double scale = x.norm() + pin.norm() + dt * v.norm() + dt * dt * gravity.norm();
          REQUIRE(cl::test::near(particles.x.col(1), x, 1e-13 * scale));
          REQUIRE(cl::test::near(particles.v.col(1), v, 1e-13 * scale / dt));
          REQUIRE(particles.x.col(0) == pin);
        }
      }
    }
  }
}
