// The speed/accuracy trade (issue 12, docs/DESIGN.md §5): every method on the
// same scenes over a range of iteration counts. Per run: wall time per step
// (median of repeats), strain error, distance to a converged reference step,
// the step's residual and objective gap (bench/step_residual.h: unlike the
// distance, defined where the step has several minimisers), and the energy
// drift over a fixed horizon. Every step is measured from two starts: the
// state an accurate trajectory reaches (the trajectory start, the default),
// and a rough one where the stiff curtains are compressed and folded (the
// hard case). What each number means, and which problem each method
// converges to: bench/README.md.
//
//   trade [--quick] [--out DIR] [--start trajectory|rough|both] [--scenes a,b] [--methods a,b] ...
//
// Writes DIR/trade.csv (one row per run), DIR/trade_scenes.csv (the scenes and
// their reference steps), DIR/trade_fastest.csv (the fastest method to each
// target of strain, distance and residual) and DIR/trade_scaling.csv (time per iteration against size);
// the drape-N scenes (lab 14's contact methods against the constrained step
// at convergence, trade_contact.cpp) DIR/trade_contact.csv.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#ifdef _OPENMP
#endif

#include <Eigen/Core>

#include "common/cli.h"
#include "common/csv.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/openmp.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/sparse.h"
#include "common/timer.h"
#include "labs/lab06_projective_dynamics/simulation.h"
#include "labs/lab13_constrained_newton/iteration.h"
#include "methods.h"
#include "step_residual.h"
#include "trade_contact.h"

namespace {

using cl::bench::Family;

// The two starts every step is measured from (bench/README.md, "The two
// starts"): the state an accurate trajectory reaches, and the rough one.
enum class Start { kTrajectory, kRough };
const char* start_name(Start start) { return start == Start::kTrajectory ? "trajectory" : "rough"; }

// The step cap grows with the springs (a step's work does): 0.3 s (quick
// 0.2 s) for 64²'s 16,002 springs, so 1.2 s on 128² and 73 ms on 32².
constexpr double kCapSprings = 16002.0;
constexpr double kCapSeconds = 0.3, kQuickCapSeconds = 0.2;

struct Options {
  bool quick = false;
  std::string out = "out/bench";
  std::vector<std::string> scenes;
  std::vector<std::string> methods;
  double stiffness = 1e6;
  int repeats = 0;        // 0: 5 (quick 3)
  int horizon = 0;        // 0: 20 (quick 10)
  int warmup = 0;         // 0: 10 (quick 5)
  double step_cap = 0.0;  // 0: per scene, by its springs (kCapSprings)
  std::string start;      // "trajectory", "rough" or "both"; empty: both (quick: trajectory)
  int threads = 1;        // OpenMP threads (the Jacobi and VBD sweeps)
};

// The methods the trade compares (lab 05's limiter solves a different
// problem again, explicit springs held in a band: only the extremes run it).
const std::vector<std::string> kTradeMethods{"gs-pbd", "jacobi-pbd", "hpbd", "xpbd", "pd",
                                             "newton", "kkt",        "schur", "schur-kg",
                                             "pd-chebyshev", "pd-lbfgs", "jacobi-chebyshev", "vbd",
                                             "vbd-chebyshev", "constrained-newton",
                                             "constrained-newton-drop"};
const std::vector<std::string> kAllScenes{"rope-100", "curtain-16", "curtain-32", "curtain-64", "curtain-128",
                                          "drape-32"};
const std::vector<std::string> kQuickScenes{"rope-100", "curtain-16", "curtain-32", "drape-16"};

// The shared scenes, with every spring of stiffness k (N/m). The gravity has a
// breeze along z (as lab 06's curtains) so that the cloth bellies out and
// most springs are in tension; on 128² some are still compressed, and the
// implicit step has more than one minimiser there (reference_spread).
cl::Scene make_scene(const std::string& name, double stiffness) {
  const std::string k = cl::format_double(stiffness);
  const std::string common = R"("gravity": [0, -9.81, 3], "dt": 0.0166666666666666667, )";
  std::string text;
  if (name == "rope-100") {
    text = R"({"name": "rope-100", )" + common +
           R"("chain": {"links": 100, "length": 0.01, "mass": 0.01, "direction": [1, 0, 0], "pin": "first", )"
           R"("stiffness": )" + k + "}}";
  } else if (name.rfind("curtain-", 0) == 0) {
    const std::string n = name.substr(8);
    if (n.empty() || n.find_first_not_of("0123456789") != std::string::npos || n.size() > 4) {
      throw cl::InputError("--scenes: unknown scene '" + name + "' (rope-100, curtain-N or drape-N, N >= 3)");
    }
    text = R"({"name": ")" + name + "\", " + common + R"("cloth": {"nx": )" + n + R"(, "ny": )" + n +
           R"(, "width": 1, "height": 1, "mass": 1, "pin": ["top"], "springs": ["structural", "shear"], )"
           R"("triangles": false, "stiffness": )" + k + "}}";
  } else {
    throw cl::InputError("--scenes: unknown scene '" + name + "' (rope-100, curtain-N or drape-N, N >= 3)");
  }
  return cl::parse_scene(text, "bench scene " + name);
}

std::vector<int> iteration_counts(const cl::bench::MethodInfo& method, bool quick) {
  if (!method.iterative) return {1};
  // Newton's K grows as far as the others' (the step cap or round-off ends
  // it): from the prediction the stiff curtains need 20 and more damped
  // iterations, and a list that stopped at 20 kept it off the accuracy end.
  // Lab 13's constrained Newton takes the same list (a few iterations reach
  // round-off, and each costs a factorization). Every K to 10: near the
  // solution a Newton iteration squares the error, so one more iteration
  // can pass both targets at once: a list that went 7, 10 measured lab 13
  // on 128² at 5.2e-6 of the start's residual (K = 7), then at 7.6e-8, the
  // reference's own floor (K = 10), and never the K that first reaches 1e-6.
  if (method.name == "newton" || method.name.rfind("constrained-newton", 0) == 0) {
    return quick ? std::vector<int>{1, 2, 3, 5, 10}
                 : std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 15, 20, 30, 50, 100, 200, 500, 1000};
  }
  return quick ? std::vector<int>{1, 3, 10, 30, 100}
               : std::vector<int>{1, 2, 5, 10, 20, 50, 100, 200, 500, 1000};
}

double total_energy(const cl::Particles& particles, const cl::Scene& scene, bool elastic) {
  double energy = cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity);
  if (elastic) energy += cl::bench::elastic_energy(particles.x, scene.springs);
  return energy;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// RMS over the particles of ‖a_p − b_p‖ (m).
double rms_distance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return a.cols() == 0 ? 0.0 : std::sqrt((a - b).colwise().squaredNorm().mean());
}

struct Run {
  std::string scene, method;
  Start start = Start::kTrajectory;
  std::string linear_solver;  // what the method's step factored with (StepOutcome)
  int iterations = 0, iterations_done = 0, repeats = 0, horizon_steps = 0;
  double step_seconds = 0, setup_seconds = 0;
  double max_strain = 0, rms_strain = 0, distance = 0, distance_max = 0, relative_distance = 0;
  double relative_distance_hard = 0;  // to the hard step (NaN when it could not be computed)
  // The step's residuals at the run's result (bench/step_residual.h), each
  // over the shared start's: the k step's (every run) and the hard step's.
  double residual_rms = 0, relative_residual = 0;
  double hard_violation_rms = 0, hard_stationarity_rms = 0, relative_residual_hard = 0;
  double objective_gap = 0;  // (g(x) − g(x_ref)) / (g(start) − g(x_ref)), lab 06's g at the scene's k
  double energy_drift = 0, energy_drift_rel = 0;
  std::string problem;  // the step or the horizon went wrong (the run's numbers are then partial)
  bool on_front = false;
};

// A second route's end against its step (second_route, below).
struct Spread {
  double relative = std::numeric_limits<double>::quiet_NaN();
  int iterations = 0;
  double gradient_norm = 0.0;  // ‖∇g‖∞ at the second route's end, N
  double seconds = 0.0;
};

struct SceneInfo {
  std::string name;
  Start start = Start::kTrajectory;
  double step_cap = 0.0;  // s, this scene's (kCapSprings)
  // The trajectory start: lab 13's iterations over its steps, the polish's,
  // and the largest |grad g| any step ended at (N); the start's wall time.
  int start_iterations = 0, start_polish_iterations = 0;
  double start_gradient = 0.0, start_seconds = 0.0;
  long long particles = 0, springs = 0;
  double reference_seconds = 0, reference_strain = 0, displacement = 0, energy_scale = 0;
  int reference_constrained_iterations = 0, reference_iterations = 0, hard_iterations = 0;
  double hard_force_error = 0.0, hard_constraint_error = 0.0, hard_max_strain = 0.0, hard_seconds = 0.0;
  int hard_newton_iterations = 0;
  double hard_gradient = 0.0;  // ‖∇g‖∞ at k = 1e9 N/m at the hard step, N
  double hard_displacement = 0.0;  // RMS of the hard step's displacement, m (0: no hard step)
  double reference_constrained_gradient = 0.0, reference_gradient = 0.0;
  Spread spread;       // the second route's end against the reference step
  // At the shared start (bench/step_residual.h): the runs' residuals are over these.
  double start_residual = 0.0;                                  // m
  double start_hard_violation = 0.0, start_hard_stationarity = 0.0, start_hard_residual = 0.0;  // m
  double objective_drop = 0.0;  // g(start) − g(x_ref), J
  // The targets' own residuals over the start's: the reference step's (k step)
  // and the k = 1e9 N/m hard step's against the true hard step's (NaN: none).
  double reference_residual = 0.0, hard_step_residual = std::numeric_limits<double>::quiet_NaN();
  Spread hard_spread;  // and against the hard step (NaN when there is none)
};

// One progress line, rewritten in place on a terminal.
class Progress {
 public:
  Progress() : tty_(isatty(fileno(stderr)) != 0) {}
  void show(const std::string& text) {
    if (!tty_) return;
    std::fprintf(stderr, "\r\033[K%s", text.c_str());
    std::fflush(stderr);
  }
  void clear() {
    if (tty_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  bool tty_;
};

// The CSV cell text (common/csv.h does not quote): no commas.
std::string csv_text(std::string text) {
  for (char& c : text) {
    if (c == ',') c = ';';
  }
  return text;
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string time_text(double seconds) {
  if (seconds < 1e-3) return format("%.3g us", seconds * 1e6);
  if (seconds < 1.0) return format("%.3g ms", seconds * 1e3);
  return format("%.3g s", seconds);
}

// The reference step from `start`: the minimiser of lab 06's objective g
// (implicit Euler). Lab 13's constrained Newton from the start, as the lab
// gives it (λ⁰ the springs' forces; compressed springs kept in K_g where the
// Cholesky takes them, a part of them dropped where it refuses, and the
// fallback on g past a fold), until |∇g| ≤ 1e-9 N (lab 06's gradient at the
// iterate), no step length lowers its merit, or 300 iterations: on every
// curtain, 128² included, this is the reference, and the polish below then
// finds nothing to do. The polish is Newton's method on g with the EXACT
// Hessian, shifted by τ M/Δt² with the smallest τ of 0, 0.01, 0.02, 0.04, …
// that factors (τ starts at a quarter of the last one, 0 below 1e-3), and a
// backtracking line search on g; once g cannot tell a decrease from its
// round-off, the full step while the gradient shrinks. It stops at
// |∇g| ≤ 1e-10 N, when the gradient stops shrinking at round-off, or after
// 300 iterations, and keeps the iterate of the smallest gradient. It is there
// for a start where lab 13 stops short (reported in the scene table:
// reference_newton_iterations > 0), and it is the second route
// (second_route). Should the constrained iteration report a problem, 500 PD
// iterations start the polish instead.
// Newton's method on lab 06's g from x (reference_step, above): the exact
// Hessian shifted by τ M/Δt² (the smallest τ of 0, 0.01, 0.02, … that
// factors), a backtracking line search on g, and at g's round-off the full
// step while it shrinks the gradient; until |∇g| ≤ 1e-10 N, the gradient stops
// shrinking at round-off, or 300 iterations. The iterate of the smallest
// ‖∇g‖∞ is kept (start_gradient: x's own).
struct Polish {
  Eigen::Matrix3Xd x;
  int iterations = 0;          // the polish iterations before the kept iterate
  double gradient_norm = 0.0;  // ‖∇g‖∞ there, N
};

Polish newton_polish(const cl::lab06::Problem& problem, const Eigen::Matrix3Xd& y, Eigen::Matrix3Xd x,
                     double start_gradient) {
  cl::SpdFactorization factor;  // the backend for the size (common/sparse.h)
  cl::lab06::HessianAssembly hessian(problem);
  const cl::MovableMap& map = problem.map;
  Eigen::VectorXd mass(3 * map.unknowns());  // M/Δt², stacked
  for (int u = 0; u < map.unknowns(); ++u) {
    mass.segment<3>(3 * u).setConstant(1.0 / (problem.inv_mass[map.particle_of[static_cast<std::size_t>(u)]] *
                                              problem.dt * problem.dt));
  }
  double g = cl::lab06::objective(problem, x, y);
  Eigen::Matrix3Xd best = x;
  double best_gradient = start_gradient;
  double tau = 0.0;
  int taken = 0;
  int best_iterations = 0;
  for (int k = 1; k <= 300 && best_gradient > 1e-10; ++k) {
    const Eigen::VectorXd gradient = cl::lab06::newton_gradient(problem, x, y);
    const double gradient_norm = gradient.cwiseAbs().maxCoeff();
    if (gradient_norm < best_gradient) {
      best = x;
      best_gradient = gradient_norm;
      best_iterations = taken;
    }
    // The exact Hessian, shifted by τ M/Δt² until it factors.
    tau = tau < 4e-3 ? 0.0 : 0.25 * tau;
    const cl::SparseMatrix& exact = hessian.update(problem, x, false);
    bool factored = false;
    for (int attempt = 0; attempt < 40 && !factored; ++attempt) {
      if (attempt > 0) tau = tau == 0.0 ? 1e-2 : 2.0 * tau;  // τ: 0, 0.01, 0.02, 0.04, …
      cl::SparseMatrix matrix = exact;
      if (tau > 0.0) {
        for (Eigen::Index r = 0; r < matrix.rows(); ++r) matrix.coeffRef(r, r) += tau * mass[r];
      }
      factored = factor.refactor(matrix);
    }
    if (!factored && !factor.refactor(hessian.update(problem, x, true))) break;
    const Eigen::VectorXd step = factor.solve(-gradient);
    const double slope = gradient.dot(step);
    auto moved = [&](double alpha) {
      Eigen::Matrix3Xd trial = x;
      for (int u = 0; u < map.unknowns(); ++u) {
        trial.col(map.particle_of[static_cast<std::size_t>(u)]) += alpha * step.segment<3>(3 * u);
      }
      return trial;
    };
    // At round-off g cannot tell a better x from a worse one (its predicted
    // decrease is below a few ulps of g): the full step while it shrinks the
    // gradient, as lab 06's Newton does.
    if (!(slope < 0.0) || -slope <= 64.0 * std::numeric_limits<double>::epsilon() * std::abs(g)) {
      const Eigen::Matrix3Xd trial = moved(1.0);
      if (cl::lab06::newton_gradient(problem, trial, y).cwiseAbs().maxCoeff() >= gradient_norm) break;
      x = trial;
    } else {
      double alpha = 1.0;
      bool accepted = false;
      for (int halving = 0; halving < 40 && !accepted; ++halving, alpha *= 0.5) {
        const Eigen::Matrix3Xd trial = moved(alpha);
        accepted = cl::lab06::objective(problem, trial, y) <= g + 1e-4 * alpha * slope;
        if (accepted) x = trial;
      }
      if (!accepted) break;
    }
    ++taken;
    g = cl::lab06::objective(problem, x, y);
  }
  const double last_gradient = cl::lab06::newton_gradient(problem, x, y).cwiseAbs().maxCoeff();
  if (last_gradient < best_gradient) {
    best = x;
    best_gradient = last_gradient;
    best_iterations = taken;
  }
  return {best, best_iterations, best_gradient};
}

// The trajectory start: `steps` steps from the scene's rest state, each the
// implicit-Euler step solved to |grad g| <= 1e-8 N (lab 06's g) by lab 13's
// constrained Newton as the lab gives it, warm from the step before (x⁰ the
// step's start, λ⁰ the springs' forces there); where lab 13 stops short (no
// step length lowers its merit, or 300 iterations), the reference's Newton
// polish on g goes on from its end. This is where a simulation is when every
// step was right. Throws when a step is not solved to 1e-8 N.
struct TrajectoryStart {
  cl::Particles particles;
  int iterations = 0, polish_iterations = 0;  // over the steps
  double worst_gradient = 0.0;               // the largest |grad g| a step ended at, N
};

TrajectoryStart trajectory_start(const cl::Scene& scene, int steps) {
  constexpr double kTolerance = 1e-8;  // N
  TrajectoryStart trajectory;
  trajectory.particles = scene.particles;
  cl::Particles& state = trajectory.particles;
  const cl::lab06::Problem problem = cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
  const cl::lab13::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
  cl::lab13::Settings settings;
  settings.gravity = scene.gravity;
  settings.iterations = 300;
  settings.tolerance = 0.0;
  for (int step = 1; step <= steps; ++step) {
    const Eigen::Matrix3Xd y = cl::lab06::predict(state, scene.gravity, scene.dt);
    Eigen::Matrix3Xd x = state.x;
    Eigen::VectorXd lambda = cl::lab13::warm_start(x, solver.springs(), {}, cl::lab13::Warm::kForces);
    const cl::lab13::StepReport report =
        solver.iterate(x, lambda, y, settings, [&](const cl::lab13::IterationRecord& record) {
          return cl::lab06::newton_gradient(problem, *record.x, y).cwiseAbs().maxCoeff() <= kTolerance;
        });
    if (!report.problem.empty()) {
      throw std::runtime_error(scene.name + ": trajectory start, step " + std::to_string(step) + ": " + report.problem);
    }
    trajectory.iterations += report.iterations_done;
    double gradient = cl::lab06::newton_gradient(problem, x, y).cwiseAbs().maxCoeff();
    if (gradient > kTolerance) {
      const Polish polish = newton_polish(problem, y, x, gradient);
      x = polish.x;
      gradient = polish.gradient_norm;
      trajectory.polish_iterations += polish.iterations;
    }
    if (!(gradient <= kTolerance)) {
      throw std::runtime_error(scene.name + ": trajectory start, step " + std::to_string(step) + ": |grad g| " +
                               format("%.1e", gradient) + " N after lab 13 and the polish, above 1e-8 N");
    }
    trajectory.worst_gradient = std::max(trajectory.worst_gradient, gradient);
    for (Eigen::Index p = 0; p < x.cols(); ++p) {
      state.v.col(p) = state.inv_mass[p] > 0.0 ? Eigen::Vector3d((x.col(p) - state.x.col(p)) / scene.dt)
                                               : Eigen::Vector3d::Zero();
    }
    state.x = x;
  }
  return trajectory;
}

struct Reference {
  cl::Particles after;
  int constrained_iterations = 0;  // lab 13's, -1 when PD started the polish
  Eigen::VectorXd lambda;          // the springs' forces −kφ at the result (empty when PD started)
  int newton_iterations = 0;
  double constrained_gradient_norm = 0.0;  // ‖∇g‖∞ after lab 13's iterations, N
  double gradient_norm = 0.0;  // ‖∇g‖∞ at the result, N
  double seconds = 0.0;
};

Reference reference_step(const cl::Scene& scene, const cl::Particles& start) {
  const cl::Timer timer;
  Reference ref;
  const cl::lab06::Problem problem = cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
  const Eigen::Matrix3Xd y = cl::lab06::predict(start, scene.gravity, scene.dt);
  ref.after = start;
  Eigen::Matrix3Xd x = start.x;
  std::vector<cl::Spring> movable_springs;  // lab 13's: without the springs between two pins
  {
    const cl::lab13::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
    movable_springs = solver.springs();
    cl::lab13::Settings settings;
    settings.gravity = scene.gravity;
    settings.iterations = 300;
    settings.tolerance = 0.0;
    Eigen::VectorXd lambda = cl::lab13::warm_start(start.x, solver.springs(), {}, cl::lab13::Warm::kForces);
    // Lab 13 as it is given (compression kept, the partial drop and the
    // fallback past a fold): until |∇g| ≤ 1e-9 N (lab 06's gradient at the
    // iterate), no step length lowers the merit, or 300 iterations (128²
    // takes about 120).
    const cl::lab13::StepReport report =
        solver.iterate(x, lambda, y, settings, [&](const cl::lab13::IterationRecord& record) {
          const double gradient = cl::lab06::newton_gradient(problem, *record.x, y).cwiseAbs().maxCoeff();
          return gradient <= 1e-9;
        });
    ref.constrained_iterations = report.iterations_done;
    if (report.problem.empty()) ref.lambda = lambda;
    if (!report.problem.empty()) {
      std::unique_ptr<cl::bench::Stepper> pd = cl::bench::make_stepper("pd", scene, 500);
      const cl::bench::StepOutcome outcome = pd->step(ref.after);
      if (!outcome.problem.empty()) throw std::runtime_error(scene.name + ": reference: " + outcome.problem);
      x = ref.after.x;
      ref.constrained_iterations = -1;
    }
  }
  ref.constrained_gradient_norm = cl::lab06::newton_gradient(problem, x, y).cwiseAbs().maxCoeff();
  const Polish polish = newton_polish(problem, y, x, ref.constrained_gradient_norm);
  ref.newton_iterations = polish.iterations;
  const double best_gradient = polish.gradient_norm;
  x = polish.x;
  ref.gradient_norm = best_gradient;
  // The hard step starts from the springs' forces at the result (the polish
  // may have moved it far from the constrained iteration's λ).
  if (ref.lambda.size() != 0) ref.lambda = cl::lab13::warm_start(x, movable_springs, {}, cl::lab13::Warm::kForces);
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    ref.after.v.col(p) = start.inv_mass[p] > 0.0 ? Eigen::Vector3d((x.col(p) - start.x.col(p)) / scene.dt)
                                                 : Eigen::Vector3d::Zero();
  }
  ref.after.x = x;
  ref.seconds = timer.seconds();
  return ref;
}

// A second route to a step: lab 06's Newton with the shifted exact Hessian
// (newton_polish) from the start alone, without lab 13's stage. Where g has
// one minimiser near the start both routes end at it and the spread (their
// distance over the step's displacement) is round-off; where it has several
// (a compressed stretch folds one way or another: 128²'s k step, 32²'s hard
// step, bench/README.md, run I), they can end at different ones; and at
// k = 1e9 N/m a gradient at round-off still leaves the soft directions loose
// (128²'s hard routes end 1.3e-4 apart). Either way no method can be said to
// be nearer the step than the spread: the targets below it are unresolved.
// NaN when the second route does not converge (|∇g| above `tolerance`, the
// step's own: 1e-8 N for the k step, 1e-6 N for the hard step at k = 1e9 N/m).
Spread second_route(const cl::lab06::Problem& problem, const cl::Particles& start, const Eigen::Matrix3Xd& y,
                    const Eigen::Matrix3Xd& step, double tolerance) {
  const cl::Timer timer;
  const Polish second =
      newton_polish(problem, y, start.x, cl::lab06::newton_gradient(problem, start.x, y).cwiseAbs().maxCoeff());
  Spread spread;
  spread.iterations = second.iterations;
  spread.gradient_norm = second.gradient_norm;
  const double displacement = rms_distance(step, start.x);
  if (second.gradient_norm <= tolerance && displacement > 0.0) {
    spread.relative = rms_distance(second.x, step) / displacement;
  }
  spread.seconds = timer.seconds();
  return spread;
}

// One line on a second route's end (`what`: "the reference", "the hard step").
void print_spread(const std::string& scene, const Spread& spread, const char* what) {
  if (std::isnan(spread.relative)) {
    std::printf("%-12s second route to %s (newton alone) not converged: |grad g| %.1e N after %d iterations (%s); "
                "its distances are not checked for a second minimiser\n",
                scene.c_str(), what, spread.gradient_norm, spread.iterations, time_text(spread.seconds).c_str());
  } else {
    std::printf("%-12s second route to %s (newton alone, %d iterations to |grad g| %.1e N, %s) ends %.1e of its "
                "move from it%s\n",
                scene.c_str(), what, spread.iterations, spread.gradient_norm, time_text(spread.seconds).c_str(),
                spread.relative,
                spread.relative > 1e-6 ? ": the routes disagree, distances below that are unresolved" : "");
  }
  std::fflush(stdout);
}

// The hard family's own step, beside the k step: the M-norm projection of the
// prediction onto the constraints. With C = 0 the curtains' structural and
// shear springs are a redundant set (lab 07's KKT matrix is singular there,
// lab 13 reports it), so the step is taken at k = 1e9 N/m (C = 1e-9 m/N), a
// thousand times the scene's k: its strain, of order m g / k, is 1e-3 of the
// k step's. Lab 13's constrained Newton from the k step's x and its springs'
// forces, compressed springs kept (dropped, or at k = 1e10 N/m and more, it
// stalls on 32² and 64²; no LU rescue), until its constraint error (max
// |φ + Cλ| over the mean rest length) is ≤ 1e-12 and its force error ≤ 1e-9,
// at most 30 iterations or 30 s. Where it does not get there (128²: the same
// non-convexity as the k step's, every iteration damped to α = 2⁻¹⁰), the
// reference step's Newton polish on g at k = 1e9 N/m takes over from the k
// step, and the step counts when its |∇g| is ≤ 1e-6 N (the constrained
// route's force error 1e-9 is about 1e-8 N; round-off in g's gradient grows
// with k). Otherwise the scene has no hard step (relative_distance_hard NaN).
constexpr double kHardStiffness = 1e9;  // N/m

// The scene's springs at kHardStiffness: the hard step's.
std::vector<cl::Spring> hard_springs(const cl::Scene& scene) {
  std::vector<cl::Spring> springs = scene.springs;
  for (cl::Spring& spring : springs) spring.stiffness = kHardStiffness;
  return springs;
}

struct HardStep {
  Eigen::Matrix3Xd x;  // empty when it failed
  int iterations = 0;         // lab 13's
  int newton_iterations = 0;  // the polish's (0: not needed)
  double force_error = 0.0, constraint_error = 0.0, max_strain = 0.0, seconds = 0.0;
  double gradient_norm = 0.0;  // ‖∇g‖∞ of lab 06's objective at k = 1e9 N/m at the result, N
  std::string problem;
};

HardStep hard_step(const cl::Scene& scene, const cl::Particles& start, const Reference& reference) {
  const cl::Timer timer;
  HardStep hard;
  if (reference.lambda.size() == 0) {
    hard.problem = "no multipliers from the k step";
    return hard;
  }
  const std::vector<cl::Spring> springs = hard_springs(scene);
  const cl::lab13::Solver solver(scene.particles.inv_mass, springs, scene.dt);
  cl::lab13::Settings settings;
  settings.gravity = scene.gravity;
  settings.iterations = 30;
  settings.tolerance = 0.0;
  settings.compression = cl::lab09::Compression::kKeep;
  settings.exact_rescue = false;
  const Eigen::Matrix3Xd y = cl::lab06::predict(start, scene.gravity, scene.dt);
  Eigen::Matrix3Xd x = reference.after.x;
  Eigen::VectorXd lambda = reference.lambda;
  bool converged = false;
  const cl::lab13::StepReport report =
      solver.iterate(x, lambda, y, settings, [&](const cl::lab13::IterationRecord& record) {
        converged = record.constraint_error <= 1e-12 && record.force_error <= 1e-9;
        return converged || record.seconds > 30.0;
      });
  hard.iterations = report.iterations_done;
  hard.force_error = report.force_error;
  hard.constraint_error = report.constraint_error;
  hard.problem = report.problem;
  const cl::lab06::Problem problem = cl::lab06::make_problem(scene.particles.inv_mass, springs, scene.dt);
  if (hard.problem.empty() && !converged) {
    // From the k step (from the constrained iteration's end, whose gradient
    // is smaller, the 128² polish stopped at 2.6e-5 N after 137 iterations).
    const Eigen::Matrix3Xd& from = reference.after.x;
    const Polish polish =
        newton_polish(problem, y, from, cl::lab06::newton_gradient(problem, from, y).cwiseAbs().maxCoeff());
    hard.newton_iterations = polish.iterations;
    if (polish.gradient_norm <= 1e-6) {
      x = polish.x;
      converged = true;
    } else {
      char text[200];
      std::snprintf(text, sizeof text,
                    "not converged after %d iterations (force error %.1e, constraint error %.1e), nor the Newton "
                    "polish (|grad g| %.1e N after %d)",
                    report.iterations_done, report.force_error, report.constraint_error, polish.gradient_norm,
                    polish.iterations);
      hard.problem = text;
    }
  }
  if (hard.problem.empty()) {
    hard.x = x;
    hard.max_strain = cl::strain_stats(x, scene.springs).max;
    hard.gradient_norm = cl::lab06::newton_gradient(problem, x, y).cwiseAbs().maxCoeff();
  }
  hard.seconds = timer.seconds();
  return hard;
}

// Marks the runs of one scene on the Pareto front of (step time, max strain
// error): no other run is at least as fast and at least as accurate, and
// strictly better in one. Runs with a problem are left out.
void mark_front(std::vector<Run>& runs, std::size_t begin) {
  for (std::size_t a = begin; a < runs.size(); ++a) {
    if (!runs[a].problem.empty()) continue;
    bool dominated = false;
    for (std::size_t b = begin; b < runs.size() && !dominated; ++b) {
      if (a == b || !runs[b].problem.empty()) continue;
      dominated = runs[b].step_seconds <= runs[a].step_seconds && runs[b].max_strain <= runs[a].max_strain &&
                  (runs[b].step_seconds < runs[a].step_seconds || runs[b].max_strain < runs[a].max_strain);
    }
    runs[a].on_front = !dominated;
  }
}

int run(const Options& options) {
  // The drape-N scenes are the contact trade's (trade_contact.cpp), with the contact methods.
  std::vector<std::string> scenes, contact_scenes;
  for (const std::string& name : options.scenes.empty() ? (options.quick ? kQuickScenes : kAllScenes) : options.scenes) {
    const bool contact_scene = cl::bench::is_contact_scene(name);
    // A build without lab 14's reference (a student tree before lab 14's deadline) leaves the drape out of the
    // defaults, and refuses it by name.
    if (contact_scene && cl::bench::contact_methods().empty()) {
      if (options.scenes.empty()) continue;
      throw cl::InputError("--scenes: " + name + " is lab 14's drape, whose reference this tree does not have (" +
                           cl::bench::kNoContactMethods + ")");
    }
    (contact_scene ? contact_scenes : scenes).push_back(name);
  }
  std::vector<std::string> methods, contact_methods;
  for (const std::string& method : options.methods.empty() ? kTradeMethods : options.methods) {
    try {
      (cl::bench::models_colliders(cl::bench::method_info(method)) ? contact_methods : methods).push_back(method);
    } catch (const std::invalid_argument& error) {
      throw cl::InputError(std::string("--methods: ") + error.what());
    }
  }
  if (!options.methods.empty() && contact_methods.empty() && !contact_scenes.empty()) {
    throw cl::InputError("--methods: the drape scenes run only contact-pbd, contact-xpbd or contact-constrained");
  }
  if (!options.methods.empty() && methods.empty() && !scenes.empty()) {
    throw cl::InputError("--methods: " + scenes.front() + " has no colliders; the contact methods run on drape-N");
  }
  cl::bench::ContactTradeOptions contact;
  contact.scenes = contact_scenes;
  contact.methods = contact_methods;
  contact.quick = options.quick;
  contact.out = options.out;
  const int repeats = options.repeats > 0 ? options.repeats : (options.quick ? 3 : 5);
  contact.repeats = repeats;
  const int horizon = options.horizon > 0 ? options.horizon : (options.quick ? 10 : 20);
  const int warmup = options.warmup > 0 ? options.warmup : (options.quick ? 5 : 10);
  // The step cap: --step-cap on every scene, or by the scene's springs.
  const double cap_per_spring = (options.quick ? kQuickCapSeconds : kCapSeconds) / kCapSprings;
  std::vector<Start> starts;
  const std::string start_option = options.start.empty() ? (options.quick ? "trajectory" : "both") : options.start;
  if (start_option == "trajectory" || start_option == "both") starts.push_back(Start::kTrajectory);
  if (start_option == "rough" || start_option == "both") starts.push_back(Start::kRough);
  if (starts.empty()) {
    throw cl::InputError("--start: '" + options.start + "' is not trajectory, rough or both");
  }
  std::string caps;  // the header's "curtain-64 300 ms, ..."
  for (const std::string& name : scenes) {
    const cl::Scene scene = make_scene(name, options.stiffness);  // bad names fail before any work
    caps += (caps.empty() ? "" : ", ") + name + " " + time_text(cap_per_spring * static_cast<double>(scene.springs.size()));
  }
  cl::start_run(options.out);
#ifdef _OPENMP
  cl::set_openmp_threads(options.threads);
  cl::set_blas_threads(options.threads);  // CHOLMOD's BLAS too: serial methods, timed side by side
#endif

  if (!contact_scenes.empty()) cl::bench::check_contact_trade(contact);
  if (!scenes.empty()) {
    const std::string cap_text =
        options.step_cap > 0.0 ? time_text(options.step_cap) + " on every scene (--step-cap)"
                               : time_text(cap_per_spring * kCapSprings) + " per 16002 springs (" + caps + ")";
    std::printf("trade: %zu scenes x %zu methods, start %s, k = %g N/m, %d repeats, horizon %d steps (from the "
                "trajectory start), warm-up %d steps, K grows while a step takes < %s, %d thread(s)\n",
                scenes.size(), methods.size(), start_option.c_str(), options.stiffness, repeats, horizon, warmup,
                cap_text.c_str(), options.threads);
  }
  std::fflush(stdout);
  const cl::Timer total;
  Progress progress;
  std::vector<Run> runs;
  std::vector<SceneInfo> infos;
  double residual_seconds = 0.0;  // the runs' residuals and gaps (the summary says what they cost)

  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const cl::Scene scene = make_scene(scenes[s], options.stiffness);
    const double scene_cap =
        options.step_cap > 0.0 ? options.step_cap : cap_per_spring * static_cast<double>(scene.springs.size());
    for (const Start start_kind : starts) {
      SceneInfo info;
      info.name = scene.name;
      info.start = start_kind;
      info.step_cap = scene_cap;
      info.particles = scene.particles.size();
      info.springs = static_cast<long long>(scene.springs.size());
      const std::string where = "[" + std::to_string(s + 1) + "/" + std::to_string(scenes.size()) + " " + scene.name +
                                ", " + start_name(start_kind) + " start]";
      const std::string label = scene.name + " (" + start_name(start_kind) + ")";

      // The start (bench/README.md, "The two starts"): `warmup` steps from the
      // scene's rest state, each solved to |grad g| <= 1e-8 N by lab 13 (the
      // trajectory start), or of PD with 100 iterations (the rough start: on
      // the stiff curtains it leaves the cloth compressed and folded). The
      // reference step from there is lab 13's, to round-off.
      progress.show(where + " warm-up");
      const cl::Timer warmup_timer;
      cl::Particles start = scene.particles;
      if (start_kind == Start::kTrajectory) {
        const TrajectoryStart trajectory = trajectory_start(scene, warmup);
        start = trajectory.particles;
        info.start_iterations = trajectory.iterations;
        info.start_polish_iterations = trajectory.polish_iterations;
        info.start_gradient = trajectory.worst_gradient;
      } else {
        std::unique_ptr<cl::bench::Stepper> warm = cl::bench::make_stepper("pd", scene, 100);
        for (int w = 0; w < warmup; ++w) {
          const cl::bench::StepOutcome outcome = warm->step(start);
          if (!outcome.problem.empty()) throw std::runtime_error(scene.name + ": warm-up: " + outcome.problem);
        }
      }
      info.start_seconds = warmup_timer.seconds();
      const Reference reference = reference_step(scene, start);
      const cl::Particles& converged = reference.after;
      info.reference_seconds = reference.seconds;
      info.reference_constrained_iterations = reference.constrained_iterations;
      info.reference_iterations = reference.newton_iterations;
      info.reference_constrained_gradient = reference.constrained_gradient_norm;
      info.reference_gradient = reference.gradient_norm;
      info.reference_strain = cl::strain_stats(converged.x, scene.springs).max;
      info.displacement = rms_distance(converged.x, start.x);
      info.energy_scale = cl::energy_scale(start, scene.gravity, scene.dt);
      progress.clear();
      if (start_kind == Start::kTrajectory) {
        std::printf("%-12s trajectory start: %d steps of constrained newton (%d iterations, then newton %d), each to "
                    "|grad g| <= %.1e N (%s); step cap %s\n",
                    scene.name.c_str(), warmup, info.start_iterations, info.start_polish_iterations, info.start_gradient,
                    time_text(info.start_seconds).c_str(), time_text(scene_cap).c_str());
      } else {
        std::printf("%-12s rough start: %d steps of pd (100 iterations) (%s); step cap %s\n", scene.name.c_str(), warmup,
                    time_text(info.start_seconds).c_str(), time_text(scene_cap).c_str());
      }
      std::printf("%-12s reference step (constrained newton %d iterations to |grad g| %.1e N, newton %d to %.1e N, %s)\n",
                  label.c_str(), info.reference_constrained_iterations, info.reference_constrained_gradient,
                  info.reference_iterations, info.reference_gradient, time_text(info.reference_seconds).c_str());
      std::fflush(stdout);
      progress.show(where + " second route");
      const cl::lab06::Problem k_problem =
          cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
      const Eigen::Matrix3Xd y = cl::lab06::predict(start, scene.gravity, scene.dt);
      info.spread = second_route(k_problem, start, y, converged.x, 1e-8);
      progress.clear();
      print_spread(label, info.spread, "the reference");
      progress.show(where + " hard step");
      const HardStep hard = hard_step(scene, start, reference);
      info.hard_iterations = hard.iterations;
      info.hard_force_error = hard.force_error;
      info.hard_constraint_error = hard.constraint_error;
      info.hard_max_strain = hard.max_strain;
      info.hard_seconds = hard.seconds;
      info.hard_newton_iterations = hard.newton_iterations;
      info.hard_gradient = hard.gradient_norm;
      if (hard.x.cols() == start.x.cols()) info.hard_displacement = rms_distance(hard.x, start.x);
      progress.clear();
      if (info.hard_displacement > 0.0) {
        std::printf("%-12s hard step (k = %.0e N/m, constrained newton %d iterations, force error %.1e, constraint "
                    "error %.1e, then newton %d; |grad g| %.1e N, %s)\n",
                    label.c_str(), kHardStiffness, info.hard_iterations, info.hard_force_error, info.hard_constraint_error,
                    info.hard_newton_iterations, info.hard_gradient, time_text(info.hard_seconds).c_str());
      } else {
        std::printf("%-12s hard step not computed: %s\n", label.c_str(), hard.problem.c_str());
      }
      std::fflush(stdout);
      if (info.hard_displacement > 0.0) {
        progress.show(where + " second route to the hard step");
        info.hard_spread = second_route(cl::lab06::make_problem(scene.particles.inv_mass, hard_springs(scene), scene.dt),
                                        start, y, hard.x, 1e-6);
        progress.clear();
        print_spread(label, info.hard_spread, "the hard step");
      }
      // The residuals' and the objective gap's scales: their values at the
      // start, where every method begins (relative_residual = 1 there).
      info.start_residual = cl::bench::step_residual(k_problem, start.x, y);
      cl::SpdFactorization delassus;  // the hard residuals' J M⁻¹ Jᵀ: one pattern per scene
      const cl::bench::HardResidual start_hard = cl::bench::hard_residual(k_problem, start.x, y, &delassus);
      info.start_hard_violation = start_hard.violation;
      info.start_hard_stationarity = start_hard.stationarity;
      info.start_hard_residual = start_hard.norm();
      const double reference_objective = cl::lab06::objective(k_problem, converged.x, y);
      info.objective_drop = cl::lab06::objective(k_problem, start.x, y) - reference_objective;
      info.reference_residual = cl::bench::step_residual(k_problem, converged.x, y) / info.start_residual;
      if (info.hard_displacement > 0.0) {
        const cl::bench::HardResidual at_hard = cl::bench::hard_residual(k_problem, hard.x, y, &delassus);
        info.hard_step_residual = at_hard.norm() / info.start_hard_residual;
      }
      std::printf("%-12s at the start: step residual %.2e m, hard step's violation %.2e m and stationarity %.2e m; "
                  "g(start) - g(reference) %.3e J; relative residuals of the reference %.1e, of the hard step %.1e\n",
                  label.c_str(), info.start_residual, info.start_hard_violation, info.start_hard_stationarity,
                  info.objective_drop, info.reference_residual, info.hard_step_residual);
      std::fflush(stdout);
      infos.push_back(info);

      const std::size_t first_run = runs.size();
      for (const std::string& method_name : methods) {
        const cl::bench::MethodInfo& method = cl::bench::method_info(method_name);
        if (method.grid_only && scene.grid_nx == 0) continue;
        const bool elastic = method.family != Family::kHard;
        const cl::Timer method_timer;
        int done_runs = 0;
        for (const int k : iteration_counts(method, options.quick)) {
          progress.show(where + " " + method.name + " K=" + std::to_string(k) + "  (" +
                        format("%.0f s", total.seconds()) + ")");
          Run r;
          r.scene = scene.name;
          r.start = start_kind;
          r.method = method.name;
          r.iterations = k;
          const cl::Timer setup;
          std::unique_ptr<cl::bench::Stepper> stepper = cl::bench::make_stepper(method.name, scene, k);
          r.setup_seconds = setup.seconds();

          // Repeats of the one step from the start, with one solver (its factor
          // and symbolic analysis reused, as in a run). The first repeat's
          // result is the one measured.
          std::vector<double> times;
          cl::Particles one;
          double timed = 0.0;
          for (int rep = 0; rep < 200 && (rep < repeats || timed < 0.02); ++rep) {  // short steps: more repeats
            cl::Particles state = start;
            const cl::Timer step_timer;
            const cl::bench::StepOutcome outcome = stepper->step(state);
            times.push_back(step_timer.seconds());
            timed += times.back();
            if (rep == 0) {
              one = state;
              r.iterations_done = outcome.iterations;
              r.problem = outcome.problem;
              r.linear_solver = outcome.linear_solver;
            }
            if (!outcome.problem.empty() || times.front() > 2.0 * scene_cap) break;  // slow: one timing will do
          }
          r.repeats = static_cast<int>(times.size());
          r.step_seconds = median(times);
          const cl::StrainStats strain = cl::strain_stats(one.x, scene.springs);
          r.max_strain = strain.max;
          r.rms_strain = strain.rms;
          r.distance = rms_distance(one.x, converged.x);
          r.distance_max = (one.x - converged.x).colwise().norm().maxCoeff();
          r.relative_distance = info.displacement > 0.0 ? r.distance / info.displacement : 0.0;
          r.relative_distance_hard = info.hard_displacement > 0.0
                                         ? rms_distance(one.x, hard.x) / info.hard_displacement
                                         : std::numeric_limits<double>::quiet_NaN();
          // Residuals (bench/step_residual.h) over the start's, every run both:
          // each family is judged by its own, as by its own distance.
          const cl::Timer residual_timer;
          r.residual_rms = cl::bench::step_residual(k_problem, one.x, y);
          r.relative_residual = r.residual_rms / info.start_residual;
          const cl::bench::HardResidual hard_residual = cl::bench::hard_residual(k_problem, one.x, y, &delassus);
          r.hard_violation_rms = hard_residual.violation;
          r.hard_stationarity_rms = hard_residual.stationarity;
          r.relative_residual_hard = hard_residual.norm() / info.start_hard_residual;
          r.objective_gap = (cl::lab06::objective(k_problem, one.x, y) - reference_objective) / info.objective_drop;
          residual_seconds += residual_timer.seconds();

          // The horizon: `horizon` steps with one solver, from the trajectory
          // start only (a trajectory goes on from a state like it; the rough
          // start is the one step's hard case).
          if (start_kind != Start::kTrajectory) {
          r.energy_drift = r.energy_drift_rel = std::numeric_limits<double>::quiet_NaN();
        } else if (r.problem.empty()) {
            std::unique_ptr<cl::bench::Stepper> runner = cl::bench::make_stepper(method.name, scene, k);
            cl::Particles state = start;
            const double e0 = total_energy(state, scene, elastic);
            for (int step = 1; step <= horizon; ++step) {
              const cl::bench::StepOutcome outcome = runner->step(state);
              std::string trouble = outcome.problem;
              if (trouble.empty()) trouble = cl::health_problem(state, cl::strain_stats(state.x, scene.springs));
              if (!trouble.empty()) {
                r.problem = "horizon step " + std::to_string(step) + ": " + trouble;
                break;
              }
              r.horizon_steps = step;
            }
            r.energy_drift = total_energy(state, scene, elastic) - e0;
            r.energy_drift_rel = info.energy_scale > 0.0 ? r.energy_drift / info.energy_scale : 0.0;
          }
          runs.push_back(r);
          ++done_runs;
          // More iterations would take too long, or change nothing (Newton stopped early).
          if (r.step_seconds > scene_cap || (method.iterative && r.iterations_done < k) || !r.problem.empty()) break;
        }
        progress.clear();
        const Run& last = runs.back();
        std::printf("%-12s %-10s %2d runs, K up to %4d: max strain %.2e, %s per step  (%.1f s)\n", label.c_str(),
                    method.name.c_str(), done_runs, last.iterations, last.max_strain, time_text(last.step_seconds).c_str(),
                    method_timer.seconds());
        std::fflush(stdout);
      }
      mark_front(runs, first_run);
    }
  }
  progress.clear();
  if (!contact_scenes.empty()) cl::bench::run_contact_trade(contact);
  if (scenes.empty()) return 0;  // only drape scenes: trade_contact.csv is their output

  // ---------------------------------------------------------------- output
  cl::CsvTable table({"scene", "start", "particles", "springs", "method", "family", "lab", "linear_solver", "iterations", "iterations_done",
                      "step_seconds", "seconds_per_iteration", "repeats", "setup_seconds", "max_strain", "rms_strain",
                      "distance_rms", "distance_max", "relative_distance", "relative_distance_hard", "residual_rms",
                      "relative_residual", "hard_violation_rms", "hard_stationarity_rms", "relative_residual_hard",
                      "objective_gap", "horizon_steps", "energy_drift", "energy_drift_rel", "on_front", "problem"});
  auto info_of = [&](const Run& r) -> const SceneInfo& {
    return *std::find_if(infos.begin(), infos.end(),
                         [&](const SceneInfo& i) { return i.name == r.scene && i.start == r.start; });
  };
  for (const Run& r : runs) {
    const cl::bench::MethodInfo& method = cl::bench::method_info(r.method);
    const SceneInfo& info = info_of(r);
    table.add_row({r.scene, std::string(start_name(r.start)), info.particles, info.springs, r.method, std::string(cl::bench::family_name(method.family)),
                   method.lab, r.linear_solver, static_cast<long long>(r.iterations), static_cast<long long>(r.iterations_done),
                   r.step_seconds, r.step_seconds / std::max(1, r.iterations_done), static_cast<long long>(r.repeats),
                   r.setup_seconds, r.max_strain, r.rms_strain, r.distance, r.distance_max, r.relative_distance, r.relative_distance_hard,
                   r.residual_rms, r.relative_residual, r.hard_violation_rms, r.hard_stationarity_rms,
                   r.relative_residual_hard, r.objective_gap, static_cast<long long>(r.horizon_steps), r.energy_drift,
                   r.energy_drift_rel,
                   static_cast<long long>(r.on_front ? 1 : 0), csv_text(r.problem)});
  }
  table.write(cl::join_path(options.out, "trade.csv"));

  cl::CsvTable scene_table({"scene", "start", "particles", "springs", "stiffness", "dt", "warmup_steps", "step_cap",
                            "start_constrained_newton_iterations", "start_newton_iterations", "start_gradient_norm",
                            "start_seconds", "reference_constrained_newton_iterations",
                            "reference_constrained_gradient_norm", "reference_newton_iterations", "reference_gradient_norm",
                            "reference_seconds", "reference_max_strain", "step_displacement_rms", "energy_scale",
                            "hard_iterations", "hard_force_error", "hard_constraint_error", "hard_max_strain",
                            "hard_seconds", "hard_displacement_rms", "hard_newton_iterations",
                            "hard_gradient_norm", "second_route_iterations", "second_route_gradient_norm",
                            "second_route_seconds", "reference_spread", "hard_second_route_iterations",
                            "hard_second_route_gradient_norm", "hard_second_route_seconds", "hard_spread",
                            "start_residual", "start_hard_violation", "start_hard_stationarity", "objective_drop",
                            "reference_relative_residual", "hard_relative_residual_hard"});
  for (const SceneInfo& info : infos) {
    scene_table.add_row({info.name, std::string(start_name(info.start)), info.particles, info.springs,
                         options.stiffness, 1.0 / 60.0, static_cast<long long>(warmup), info.step_cap,
                         static_cast<long long>(info.start_iterations),
                         static_cast<long long>(info.start_polish_iterations), info.start_gradient, info.start_seconds,
                         static_cast<long long>(info.reference_constrained_iterations),
                         info.reference_constrained_gradient, static_cast<long long>(info.reference_iterations),
                         info.reference_gradient,
                         info.reference_seconds, info.reference_strain, info.displacement, info.energy_scale,
                         static_cast<long long>(info.hard_iterations), info.hard_force_error, info.hard_constraint_error,
                         info.hard_max_strain, info.hard_seconds, info.hard_displacement,
                         static_cast<long long>(info.hard_newton_iterations), info.hard_gradient,
                         static_cast<long long>(info.spread.iterations), info.spread.gradient_norm, info.spread.seconds,
                         info.spread.relative, static_cast<long long>(info.hard_spread.iterations),
                         info.hard_spread.gradient_norm, info.hard_spread.seconds, info.hard_spread.relative,
                         info.start_residual, info.start_hard_violation, info.start_hard_stationarity,
                         info.objective_drop, info.reference_residual, info.hard_step_residual});
  }
  scene_table.write(cl::join_path(options.out, "trade_scenes.csv"));

  // The fastest run to each target, per scene: of the max strain error (the
  // issue's table) and of the distance to the reference step relative to the
  // step's displacement (which a method can only reach by solving the step),
  // and of the distance to the hard step (the hard family's own target; NaN,
  // never a winner, when the scene has none). A distance target below its
  // step's spread (two minimisers farther apart than it) is unresolved:
  // method "unresolved", no winner. The residuals of the k step and of the
  // hard step, over the start's, are 0 at every solution alike: never
  // unresolved, and their targets are 1e-3 and 1e-6.
  constexpr int kMeasures = 5;
  constexpr std::size_t kTargets = 2;
  const char* const measures[kMeasures] = {"max_strain", "relative_distance", "relative_distance_hard",
                                           "relative_residual", "relative_residual_hard"};
  auto targets_of = [](int measure) {
    return measure >= 3 ? std::array<double, kTargets>{1e-3, 1e-6} : std::array<double, kTargets>{1e-2, 1e-3};
  };
  auto value_of = [](const Run& r, int measure) {
    switch (measure) {
      case 0: return r.max_strain;
      case 1: return r.relative_distance;
      case 2: return r.relative_distance_hard;
      case 3: return r.relative_residual;
      default: return r.relative_residual_hard;
    }
  };
  cl::CsvTable fastest({"scene", "start", "measure", "target", "method", "iterations", "step_seconds", "value"});
  // best[measure][scene][target]
  std::vector<std::vector<std::vector<const Run*>>> best(
      kMeasures, std::vector<std::vector<const Run*>>(infos.size(), std::vector<const Run*>(kTargets, nullptr)));
  auto spread_of = [&](int measure, std::size_t scene) {
    return measure == 1 ? infos[scene].spread.relative
                        : measure == 2 ? infos[scene].hard_spread.relative : std::numeric_limits<double>::quiet_NaN();
  };
  auto unresolved = [&](int measure, std::size_t scene, std::size_t target) {
    return spread_of(measure, scene) > targets_of(measure)[target];
  };
  for (int m = 0; m < kMeasures; ++m) {
    const std::array<double, kTargets> targets = targets_of(m);
    for (std::size_t s = 0; s < infos.size(); ++s) {
      for (std::size_t t = 0; t < kTargets; ++t) {
        const Run*& b = best[static_cast<std::size_t>(m)][s][t];
        if (unresolved(m, s, t)) {
          fastest.add_row({infos[s].name, std::string(start_name(infos[s].start)), std::string(measures[m]), targets[t], std::string("unresolved"), 0LL, 0.0,
                           spread_of(m, s)});
          continue;
        }
        for (const Run& r : runs) {
          if (r.scene != infos[s].name || r.start != infos[s].start || !r.problem.empty() || !(value_of(r, m) <= targets[t])) continue;
          if (!b || r.step_seconds < b->step_seconds) b = &r;
        }
        if (b) {
          fastest.add_row({infos[s].name, std::string(start_name(infos[s].start)), std::string(measures[m]), targets[t], b->method,
                           static_cast<long long>(b->iterations), b->step_seconds, value_of(*b, m)});
        } else {
          fastest.add_row({infos[s].name, std::string(start_name(infos[s].start)), std::string(measures[m]), targets[t], std::string("none"), 0LL, 0.0, 0.0});
        }
      }
    }
  }
  fastest.write(cl::join_path(options.out, "trade_fastest.csv"));

  // Time per iteration against size, on the curtains, from the first start
  // run (the trajectory start's when both are): per method the run with
  // the iteration count nearest 10 (a direct solve: its one solve).
  cl::CsvTable scaling({"method", "scene", "particles", "springs", "iterations_done", "seconds_per_iteration"});
  std::vector<std::pair<std::string, std::pair<double, int>>> exponents;
  for (const std::string& method_name : methods) {
    std::vector<double> log_n, log_t;
    for (const SceneInfo& info : infos) {
      if (info.name.rfind("curtain-", 0) != 0 || info.start != starts.front()) continue;
      const Run* pick = nullptr;
      for (const Run& r : runs) {
        if (r.scene != info.name || r.start != info.start || r.method != method_name || r.iterations_done < 1) continue;
        if (!pick || std::abs(std::log(r.iterations / 10.0)) < std::abs(std::log(pick->iterations / 10.0))) pick = &r;
      }
      if (!pick) continue;
      const double per = pick->step_seconds / pick->iterations_done;
      scaling.add_row({method_name, info.name, info.particles, info.springs,
                       static_cast<long long>(pick->iterations_done), per});
      log_n.push_back(std::log(static_cast<double>(info.particles)));
      log_t.push_back(std::log(per));
    }
    if (log_n.size() >= 2) {
      const Eigen::Map<Eigen::VectorXd> xs(log_n.data(), static_cast<Eigen::Index>(log_n.size()));
      const Eigen::Map<Eigen::VectorXd> ys(log_t.data(), static_cast<Eigen::Index>(log_t.size()));
      const Eigen::VectorXd dx = xs.array() - xs.mean();
      const Eigen::VectorXd dy = ys.array() - ys.mean();
      exponents.push_back({method_name, {dx.dot(dy) / dx.squaredNorm(), static_cast<int>(log_n.size())}});
    }
  }
  scaling.write(cl::join_path(options.out, "trade_scaling.csv"));

  // ---------------------------------------------------------------- summary
  std::printf("\ntrade: %zu runs on %zu scenes in %.0f s (of which the runs' residuals %.1f s); CSV in %s\n",
              runs.size(), infos.size(), total.seconds(), residual_seconds, options.out.c_str());
  const char* const titles[kMeasures] = {"max strain error", "distance to the reference step / step displacement",
                                         "distance to the hard step (k = 1e9 N/m) / its displacement",
                                         "the step's residual / the start's",
                                         "the hard step's residual / the start's"};
  for (int m = 0; m < kMeasures; ++m) {
    const std::array<double, kTargets> targets = targets_of(m);
    auto bound = [](double target) {  // "<= 1e-3", not "<= 1e-03"
      std::string text = format("<= %.0e", target);
      const std::size_t zero = text.find("e-0");
      return zero == std::string::npos ? text : text.erase(zero + 2, 1);
    };
    const std::string low = bound(targets[0]), high = bound(targets[1]);
    std::printf("fastest method to %s %s and %s (median wall time per step):\n", titles[m], low.c_str(), high.c_str());
    std::printf("  %-24s %-30s %-30s\n", "scene", low.c_str(), high.c_str());
    for (std::size_t s = 0; s < infos.size(); ++s) {
      std::string cells[kTargets];
      for (std::size_t t = 0; t < kTargets; ++t) {
        const Run* b = best[static_cast<std::size_t>(m)][s][t];
        if (unresolved(m, s, t)) {
          cells[t] = "unresolved (spread " + format("%.1e", spread_of(m, s)) + ")";
          continue;
        }
        cells[t] = b ? b->method +
                           (cl::bench::method_info(b->method).iterative ? " K=" + std::to_string(b->iterations) : "") +
                           " " + time_text(b->step_seconds)
                     : "none reached";
      }
      const std::string label = infos[s].name + (starts.size() > 1 ? std::string(" (") + start_name(infos[s].start) + ")" : "");
      std::printf("  %-24s %-30s %-30s\n", label.c_str(), cells[0].c_str(), cells[1].c_str());
    }
  }
  if (!exponents.empty()) {
    std::printf("time per iteration ~ particles^p on the curtains:");
    for (const auto& [name, fit] : exponents) std::printf(" %s %.2f", name.c_str(), fit.first);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{"The speed/accuracy trade: every method on shared scenes (bench/README.md).", "trade"};
  Options options;
  app.add_flag("--quick", options.quick, "CI size: rope-100, curtain-16 and -32, fewer iterations, repeats and steps");
  app.add_option("--out", options.out, "folder for the CSV files").capture_default_str();
  const bool contact = !cl::bench::contact_methods().empty();  // lab 14's reference is in this tree
  app.add_option("--scenes", options.scenes,
                 contact ? "rope-100, curtain-N, drape-N (lab 14's drape: the contact methods; default: rope-100, "
                           "curtains 16 to 128, drape-32)"
                         : "rope-100, curtain-N (default: rope-100, curtains 16 to 128; lab 14's drape-N needs its "
                           "reference, not in this tree)")
      .delimiter(',');
  app.add_option("--methods", options.methods,
                 std::string("gs-pbd, jacobi-pbd, hpbd, xpbd, pd, newton, kkt, schur, schur-kg, pd-chebyshev, "
                             "pd-lbfgs, jacobi-chebyshev, vbd, vbd-chebyshev, constrained-newton, "
                             "constrained-newton-drop") +
                     (contact ? "; on drape-N: contact-pbd, contact-xpbd, contact-constrained" : ""))
      .delimiter(',');
  app.add_option("--stiffness", options.stiffness, "every spring's stiffness, N/m")
      .positive()
      .capture_default_str();
  app.add_option("--repeats", options.repeats, "timed repeats of each step (default 5, quick 3)")
      .range(1, 1'000'000);
  app.add_option("--horizon", options.horizon, "steps of the energy-drift run (default 20, quick 10)")
      .range(1, 1'000'000);
  app.add_option("--warmup", options.warmup, "PD steps (100 iterations) before the shared start (default 10, quick 5)")
      .range(1, 1'000'000);
  app.add_option("--step-cap", options.step_cap,
                 "stop raising K once a step takes this long, s, on every scene (default by the scene's springs: "
                 "0.3 s, quick 0.2 s, per 16002 springs, 64²'s)")
      .positive();
  app.add_option("--start", options.start,
                 "trajectory (10 steps from rest, each solved to |grad g| <= 1e-8 N by lab 13), rough (10 steps of PD, "
                 "100 iterations) or both (default both; quick trajectory)");
  app.add_option("--threads", options.threads,
                 "OpenMP threads of the parallel sweeps and BLAS threads of CHOLMOD (1: comparable timings on a shared machine)")
      .range(1, 256)
      .capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options); });
}
