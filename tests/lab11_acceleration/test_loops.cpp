// Graded tests of whole accelerated steps (given code around all five
// functions): the accelerated methods converge to lab 06's Newton minimiser,
// restarts never raise the objective, ρ = 0 is the plain iteration bit for
// bit, L-BFGS with m = 0 is projective dynamics, and its directions descend
// without the given loop's fallback.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "../lab06_projective_dynamics/test_scenes.h"
#include "accelerated.h"
#include "common/scene.h"
#include "pbd.h"
#include "tests/support/checks.h"

using cl::lab11::Method;
using Eigen::Matrix3Xd;

namespace {

struct Case {
  cl::Particles start;
  std::vector<cl::Spring> springs;
  double dt = 1.0 / 60.0;
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};
};

// A small random scene (as lab 06's tests): 8 particles, one pinned, springs
// near their rest length.
Case random_case(std::mt19937_64& rng, int trial) {
  Case c;
  c.start = lab06_test::random_particles(rng, 8);
  c.start.inv_mass[trial % 8] = 0.0;
  c.springs = lab06_test::random_springs(rng, c.start.x, 7, 0.7, 1.3, 1.0, 3.0);
  return c;
}

// lab 06's Newton step to round-off: the reference minimiser.
cl::Particles newton_step(const Case& c) {
  cl::Particles particles = c.start;
  cl::lab06::Solver solver(cl::lab06::make_problem(c.start.inv_mass, c.springs, c.dt), cl::lab06::Method::kNewton);
  cl::lab06::StepSettings settings;
  settings.gravity = c.gravity;
  settings.iterations = 100;
  const cl::lab06::StepReport report = solver.step(particles, settings);
  REQUIRE(report.problem.empty());
  REQUIRE(report.converged);
  return particles;
}

// One step of `method`, with the objective (or merit) after every iteration.
cl::Particles run(const Case& c, Method method, cl::lab11::Settings settings, std::vector<double>* values = nullptr,
                  cl::lab11::StepReport* report_out = nullptr) {
  cl::Particles particles = c.start;
  cl::lab11::Solver solver(c.start.inv_mass, c.springs, c.dt);
  settings.gravity = c.gravity;
  const cl::lab11::StepReport report = solver.step(particles, method, settings, [&](const auto& record) {
    if (values) values->push_back(record.objective);
    return false;
  });
  REQUIRE(report.problem.empty());
  if (report_out) *report_out = report;
  return particles;
}

double moved(const cl::Particles& a, const cl::Particles& b) { return (a.x - b.x).cwiseAbs().maxCoeff(); }

}  // namespace

TEST_CASE("Chebyshev-accelerated PD converges to the plain PD and Newton minimiser to 1e-8", "[lab11][pts=2]") {
  std::mt19937_64 rng(1111);
  for (int trial = 0; trial < 4; ++trial) {
    const Case c = random_case(rng, trial);
    CAPTURE(trial, c.start.x, c.start.v, c.start.inv_mass.transpose());
    const cl::Particles newton = newton_step(c);
    const double motion = moved(newton, c.start);
    cl::lab11::Solver solver(c.start.inv_mass, c.springs, c.dt);
    cl::lab11::Settings settings;
    settings.gravity = c.gravity;
    const double estimated = solver.estimate_rho(c.start, Method::kPd, settings);
    CAPTURE(estimated);
    REQUIRE(estimated >= 0.0);
    REQUIRE(estimated < 1.0);
    for (const double rho : {estimated, 0.5, 0.95}) {
      settings.rho = rho;
      settings.iterations = 4000;
      settings.delay = trial % 2 == 0 ? 1 : 10;
      const cl::Particles accelerated = run(c, Method::kPdChebyshev, settings);
      CAPTURE(rho, settings.delay);
      REQUIRE(cl::test::near(accelerated.x, newton.x, 1e-8 * motion));
      REQUIRE(cl::test::near(accelerated.v, newton.v, 1e-8 * motion / c.dt));
    }
    settings.iterations = 20000;
    const cl::Particles plain = run(c, Method::kPd, settings);
    REQUIRE(cl::test::near(plain.x, newton.x, 1e-8 * motion));
  }
}

TEST_CASE("the objective after a restart never exceeds the objective before it and pinned particles never move",
          "[lab11][pts=1]") {
  // The cloth of lab 06's tests, with ρ far too high (0.999) and far too low:
  // whatever ρ is, an iterate is accepted only if g did not rise, and a
  // restart takes the plain PD iterate, which never raises g.
  const cl::Scene scene = lab06_test::cloth(10, 1e4);
  Case c;
  c.start = scene.particles;
  c.springs = scene.springs;
  c.dt = scene.dt;
  c.gravity = scene.gravity;
  for (const double rho : {0.999, 0.99, 0.3}) {
    cl::lab11::Settings settings;
    settings.rho = rho;
    settings.iterations = 300;
    std::vector<double> g;
    cl::lab11::StepReport report;
    const cl::Particles after = run(c, Method::kPdChebyshev, settings, &g, &report);
    CAPTURE(rho, report.restarts);
    REQUIRE(g.size() == 301);
    for (std::size_t k = 1; k < g.size(); ++k) {
      CAPTURE(k, g[k - 1], g[k]);
      REQUIRE(std::isfinite(g[k]));
      REQUIRE(g[k] <= g[k - 1] + cl::lab11::kRestartSlack * std::abs(g[k - 1]) + 1e-15);
    }
    if (rho == 0.999) REQUIRE(report.restarts > 0);
    for (Eigen::Index p = 0; p < after.size(); ++p) {
      if (c.start.inv_mass[p] > 0.0) continue;
      CAPTURE(p);
      REQUIRE(cl::test::near(after.x.col(p), c.start.x.col(p), 0.0));
    }
  }
  // The same for accelerated Jacobi PBD (merit Σ strain²).
  for (const double rho : {0.999, 0.9}) {
    cl::lab11::Settings settings;
    settings.rho = rho;
    settings.gamma = 0.9;
    settings.iterations = 200;
    std::vector<double> merit;
    const cl::Particles after = run(c, Method::kJacobiChebyshev, settings, &merit);
    for (std::size_t k = 2; k < merit.size(); ++k) {
      CAPTURE(rho, k, merit[k - 1], merit[k]);
      REQUIRE(std::isfinite(merit[k]));
    }
    for (Eigen::Index p = 0; p < after.size(); ++p) {
      if (c.start.inv_mass[p] > 0.0) continue;
      CAPTURE(p);
      REQUIRE(cl::test::near(after.x.col(p), c.start.x.col(p), 0.0));
    }
  }
}

TEST_CASE("rho = 0 reduces the accelerated PD and Jacobi PBD steps to the plain ones bit for bit", "[lab11][pts=1]") {
  const cl::Scene scene = lab06_test::cloth(8, 1e4);
  Case c;
  c.start = scene.particles;
  c.springs = scene.springs;
  c.dt = scene.dt;
  c.gravity = scene.gravity;
  cl::lab11::Settings settings;
  settings.rho = 0.0;
  settings.iterations = 25;
  settings.delay = 3;
  const cl::Particles plain = run(c, Method::kPd, settings);
  const cl::Particles accelerated = run(c, Method::kPdChebyshev, settings);
  REQUIRE(cl::test::near(accelerated.x, plain.x, 0.0));
  REQUIRE(cl::test::near(accelerated.v, plain.v, 0.0));
  // Jacobi PBD: lab 04's step with averaged Jacobi sweeps.
  cl::Particles lab04 = c.start;
  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(c.start.size(), c.springs);
  cl::lab04::PbdSettings pbd;
  pbd.dt = c.dt;
  pbd.gravity = c.gravity;
  pbd.iterations = settings.iterations;
  pbd.projection = cl::lab04::Projection::kJacobi;
  cl::lab04::pbd_step(lab04, constraints, pbd);
  const cl::Particles jacobi = run(c, Method::kJacobiChebyshev, settings);
  REQUIRE(cl::test::near(jacobi.x, lab04.x, 0.0));
  REQUIRE(cl::test::near(jacobi.v, lab04.v, 0.0));
}

TEST_CASE("L-BFGS with m = 0 is projective dynamics and on a quadratic objective converges in one iteration",
          "[lab11][pts=2]") {
  // With H = A⁻¹ the direction is −A⁻¹∇g, PD's update; its full step meets
  // Armijo's condition for any c <= 1/2 (README.md), so the line search keeps it.
  std::mt19937_64 rng(1112);
  for (int trial = 0; trial < 3; ++trial) {
    const Case c = random_case(rng, trial);
    CAPTURE(trial, c.start.x, c.start.inv_mass.transpose());
    for (const int iterations : {1, 2, 5, 20}) {
      cl::lab11::Settings settings;
      settings.history = 0;
      settings.iterations = iterations;
      const cl::Particles pd = run(c, Method::kPd, settings);
      const cl::Particles lbfgs = run(c, Method::kPdLbfgs, settings);
      CAPTURE(iterations);
      REQUIRE(cl::test::near(lbfgs.x, pd.x, 1e-10 * (1.0 + moved(pd, c.start))));
    }
  }
  // Rest lengths 0: E = Σ k/2 ‖x_i − x_j‖², g is quadratic with Hessian A, and
  // one L-BFGS iteration (from any history size) lands on its minimiser.
  for (int trial = 0; trial < 3; ++trial) {
    Case c = random_case(rng, trial);
    for (cl::Spring& spring : c.springs) spring.rest_length = 0.0;
    const cl::lab06::Problem problem = cl::lab06::make_problem(c.start.inv_mass, c.springs, c.dt);
    const Matrix3Xd y = cl::lab06::predict(c.start, c.gravity, c.dt);
    cl::lab11::Solver solver(c.start.inv_mass, c.springs, c.dt);
    for (const int history : {0, 5}) {
      cl::lab11::Settings settings;
      settings.gravity = c.gravity;
      settings.history = history;
      settings.iterations = 1;
      Matrix3Xd x = y;
      const double start_gradient = cl::lab06::newton_gradient(problem, x, y).norm();
      const cl::lab11::StepReport report = solver.minimise(x, y, Method::kPdLbfgs, settings);
      CAPTURE(trial, history, start_gradient);
      REQUIRE(report.problem.empty());
      REQUIRE(report.iterations_done == 1);
      REQUIRE(cl::lab06::newton_gradient(problem, x, y).norm() <= 1e-10 * start_gradient);
    }
  }
}

TEST_CASE("converged L-BFGS equals the Newton minimiser to 1e-8 and g never rises over an iteration",
          "[lab11][pts=2]") {
  std::mt19937_64 rng(1113);
  for (int trial = 0; trial < 4; ++trial) {
    const Case c = random_case(rng, trial);
    CAPTURE(trial, c.start.x, c.start.v, c.start.inv_mass.transpose());
    const cl::Particles newton = newton_step(c);
    const double motion = moved(newton, c.start);
    for (const int history : {1, 5, 20}) {
      cl::lab11::Settings settings;
      settings.history = history;
      settings.iterations = 3000;
      std::vector<double> g;
      const cl::Particles lbfgs = run(c, Method::kPdLbfgs, settings, &g);
      CAPTURE(history, g.size());
      REQUIRE(cl::test::near(lbfgs.x, newton.x, 1e-8 * motion));
      for (std::size_t k = 1; k < g.size(); ++k) {
        CAPTURE(k, g[k - 1], g[k]);
        REQUIRE(g[k] <= g[k - 1] + 64.0 * 2.220446049250313e-16 * std::abs(g[k - 1]));
      }
    }
  }
}

TEST_CASE("on a well-posed scene every L-BFGS direction descends and none falls back to the PD direction", "[lab11][pts=1]") {
  // The given loop replaces a direction that is not a descent by −A⁻¹∇g and
  // forgets the history (StepReport::descent_fallbacks): a recursion of the
  // wrong sign, or one that uses a pair with sᵀy <= 0, then runs as plain PD
  // and still converges, so the cases above cannot see it. A correct
  // recursion keeps H positive definite and never needs the fallback.
  std::mt19937_64 rng(1114);
  std::vector<Case> cases;
  for (int trial = 0; trial < 3; ++trial) cases.push_back(random_case(rng, trial));
  const cl::Scene scene = lab06_test::cloth(10, 1e4);
  cases.push_back({scene.particles, scene.springs, scene.dt, scene.gravity});
  for (std::size_t index = 0; index < cases.size(); ++index) {
    for (const int history : {1, 5, 20}) {
      cl::lab11::Settings settings;
      settings.history = history;
      settings.iterations = 3000;
      cl::lab11::StepReport report;
      run(cases[index], Method::kPdLbfgs, settings, nullptr, &report);
      CAPTURE(index, history, report.iterations_done);
      REQUIRE(cl::test::at_most("descent fallbacks", report.descent_fallbacks, 0));
    }
  }
}
