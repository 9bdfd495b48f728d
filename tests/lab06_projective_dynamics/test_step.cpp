// Graded tests of whole steps (all five functions of lab 06): the objective
// never rises across PD iterations, converged PD equals Newton, one
// factorization per scene.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "projective_dynamics.h"
#include "simulation.h"
#include "test_scenes.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;

namespace {

// The objective after every PD iteration of one step.
std::vector<double> pd_objectives(cl::lab06::Solver& solver, cl::Particles& particles, const Eigen::Vector3d& gravity,
                                  int iterations) {
  std::vector<double> values;
  cl::lab06::StepSettings settings;
  settings.gravity = gravity;
  settings.iterations = iterations;
  const cl::lab06::StepReport report =
      solver.step(particles, settings, [&](const cl::lab06::IterationRecord& record) {
        values.push_back(record.objective);
        return false;
      });
  REQUIRE(report.problem.empty());
  return values;
}

}  // namespace

TEST_CASE("the objective never increases across projective dynamics iterations", "[lab06][pts=2]") {
  // g(x) = min over d of G(x, d); the local step minimises G over d, the global
  // step over x, so g(x^{k+1}) <= G(x^{k+1}, d^k) <= G(x^k, d^k) = g(x^k).
  std::mt19937_64 rng(64);
  for (int trial = 0; trial < 8; ++trial) {
    cl::Particles particles = lab06_test::random_particles(rng, 9);
    particles.inv_mass[0] = 0.0;
    // Springs far from rest (0.2 … 3 times their length), so the local step matters.
    const std::vector<cl::Spring> springs = lab06_test::random_springs(rng, particles.x, 12, 0.2, 3.0, 1.0, 5.0);
    if (trial == 7) particles.x.col(2) = particles.x.col(3);  // coincident ends
    const double dt = trial % 2 == 0 ? 1.0 / 60.0 : 0.3;
    cl::lab06::Solver solver(cl::lab06::make_problem(particles.inv_mass, springs, dt), cl::lab06::Method::kProjectiveDynamics);
    for (int step = 0; step < 3; ++step) {
      CAPTURE(trial, step, dt, particles.x, particles.v, particles.inv_mass.transpose());
      const std::vector<double> g = pd_objectives(solver, particles, Eigen::Vector3d(0.0, -9.81, 0.0), 200);
      REQUIRE(g.size() == 201);
      for (std::size_t k = 1; k < g.size(); ++k) {
        CAPTURE(k, g[k - 1], g[k]);
        REQUIRE(std::isfinite(g[k]));
        REQUIRE(g[k] <= g[k - 1] + 1e-13 * std::abs(g[k - 1]));
      }
      REQUIRE(g.back() < g.front());
    }
  }
  // The hanging cloth, stepped for a while with K = 10 and then watched.
  const cl::Scene scene = lab06_test::cloth(10, 1e4);
  cl::Particles particles = scene.particles;
  cl::lab06::Solver solver(cl::lab06::make_problem(particles.inv_mass, scene.springs, scene.dt),
                           cl::lab06::Method::kProjectiveDynamics);
  for (int step = 0; step < 20; ++step) {
    const std::vector<double> g = pd_objectives(solver, particles, scene.gravity, step % 5 == 4 ? 100 : 10);
    for (std::size_t k = 1; k < g.size(); ++k) {
      CAPTURE(step, k, g[k - 1], g[k]);
      REQUIRE(g[k] <= g[k - 1] + 1e-13 * std::abs(g[k - 1]));
    }
  }
}

TEST_CASE("converged projective dynamics equals the converged Newton step to 1e-8", "[lab06][pts=2]") {
  std::mt19937_64 rng(65);
  for (int trial = 0; trial < 4; ++trial) {
    cl::Particles start = lab06_test::random_particles(rng, 8);
    start.inv_mass[trial] = 0.0;
    const std::vector<cl::Spring> springs = lab06_test::random_springs(rng, start.x, 7, 0.7, 1.3, 1.0, 3.0);
    const double dt = 1.0 / 60.0;
    const cl::lab06::Problem problem = cl::lab06::make_problem(start.inv_mass, springs, dt);
    cl::lab06::StepSettings settings;
    settings.gravity = Eigen::Vector3d(0.0, -9.81, 0.0);
    CAPTURE(trial, start.x, start.v, start.inv_mass.transpose());

    cl::Particles newton = start;
    cl::lab06::Solver newton_solver(problem, cl::lab06::Method::kNewton);
    settings.iterations = 100;
    const cl::lab06::StepReport newton_report = newton_solver.step(newton, settings);
    CAPTURE(newton_report.iterations_done, newton_report.objective);
    REQUIRE(newton_report.problem.empty());
    REQUIRE(newton_report.converged);
    REQUIRE(newton_report.failed_decreases == 0);

    cl::Particles pd = start;
    cl::lab06::Solver pd_solver(problem, cl::lab06::Method::kProjectiveDynamics);
    settings.iterations = 20000;
    const cl::lab06::StepReport pd_report = pd_solver.step(pd, settings);
    CAPTURE(pd_report.objective);
    REQUIRE(pd_report.problem.empty());

    // Relative to how far the step moved the particles.
    const double moved = (newton.x - start.x).cwiseAbs().maxCoeff();
    CAPTURE(moved);
    REQUIRE(cl::test::near(pd.x, newton.x, 1e-8 * moved, "particle"));
    REQUIRE(cl::test::near(pd.v, newton.v, 1e-8 * moved / dt, "particle"));
  }
}

TEST_CASE("the factorization count is one per scene whatever the step count", "[lab06][pts=1]") {
  const cl::Scene scene = lab06_test::cloth(8, 1e4);
  const cl::lab06::Problem problem = cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
  cl::lab06::StepSettings settings;
  settings.gravity = scene.gravity;
  settings.iterations = 5;
  for (const int steps : {0, 1, 7, 40}) {
    cl::Particles particles = scene.particles;
    cl::lab06::Solver solver(problem, cl::lab06::Method::kProjectiveDynamics);
    const cl::lab06::RunResult result = cl::lab06::run_steps(particles, solver, settings, steps);
    CAPTURE(steps, result.problem);
    REQUIRE(result.problem.empty());
    REQUIRE(result.steps_done == steps);
    REQUIRE(result.iterations_done == 5LL * steps);
    REQUIRE(solver.factorizations() == 1);
    REQUIRE(cl::all_finite(particles.x));
  }
}
