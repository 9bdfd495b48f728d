// Lab 11 — given code: the accelerated PD, L-BFGS and PBD loops, and the run.
#include "accelerated.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/health.h"
#include "common/metrics.h"
#include "common/timer.h"
#include "gauss_seidel.h"
#include "jacobi.h"

namespace cl::lab11 {

namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

struct Named {
  Method method;
  const char* name;
};
constexpr Named kNames[] = {{Method::kPd, "pd"},
                            {Method::kPdChebyshev, "pd-chebyshev"},
                            {Method::kPdLbfgs, "pd-lbfgs"},
                            {Method::kNewton, "newton"},
                            {Method::kJacobi, "jacobi"},
                            {Method::kJacobiChebyshev, "jacobi-chebyshev"},
                            {Method::kGaussSeidel, "gauss-seidel"}};

// lab 06's tolerance rule: the relative decrease fell below tol.
bool decrease_below(double previous, double current, double tolerance) {
  if (!(previous > 0.0)) return true;
  return previous - current < tolerance * previous;
}

void check(const Settings& settings) {
  if (settings.iterations < 0) throw std::invalid_argument("iterations must be >= 0");
  if (!std::isfinite(settings.tolerance) || settings.tolerance < 0.0) {
    throw std::invalid_argument("tolerance must be finite and >= 0");
  }
  if (!std::isfinite(settings.rho) || settings.rho < 0.0 || settings.rho >= 1.0) {
    throw std::invalid_argument("rho must be in [0, 1) (got " + std::to_string(settings.rho) + ")");
  }
  if (!std::isfinite(settings.gamma) || !(settings.gamma > 0.0) || !(settings.gamma < 2.0)) {
    throw std::invalid_argument("gamma must be in (0, 2) (got " + std::to_string(settings.gamma) + ")");
  }
  if (settings.delay < 1) throw std::invalid_argument("delay must be >= 1");
  if (settings.history < 0) throw std::invalid_argument("history must be >= 0");
}

// A pinned particle is data, not an unknown: its column is put back after an
// update that mixes iterates (the expanded form is not exact for equal inputs).
void hold_pinned(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& held, const Eigen::VectorXd& inv_mass) {
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    if (!(inv_mass[p] > 0.0)) x.col(p) = held.col(p);
  }
}

// The Chebyshev schedule of Wang (2015): ω = 1 before iteration S, then the
// weights of acceleration.h counted from S (or from the last restart).
struct Schedule {
  double rho;
  int delay;
  int count = 0;  // j of the current iteration (0: not started)
  double omega = 1.0;
  double next(int k) {
    if (k >= delay) ++count;
    omega = chebyshev_weight(std::max(count, 1), rho, omega);
    return omega;
  }
  void restart() {
    count = 1;
    omega = 1.0;
  }
};

// Wall time of the method, without what is spent only for the records.
struct Clock {
  Timer timer;
  double excluded = 0.0;
  double seconds() const { return timer.seconds() - excluded; }
};

}  // namespace

const char* method_name(Method method) {
  for (const Named& named : kNames) {
    if (named.method == method) return named.name;
  }
  return "?";
}

Method method_from_name(const std::string& name) {
  for (const Named& named : kNames) {
    if (name == named.name) return named.method;
  }
  throw std::invalid_argument("unknown method '" + name + "'");
}

bool minimises_objective(Method method) {
  return method == Method::kPd || method == Method::kPdChebyshev || method == Method::kPdLbfgs ||
         method == Method::kNewton;
}

Eigen::VectorXd apply_inverse(const SpdFactorization& factor, const Eigen::VectorXd& stacked) {
  const Eigen::Index unknowns = stacked.size() / 3;
  const RowsX3 rows = Eigen::Map<const RowsX3>(stacked.data(), unknowns, 3);
  const RowsX3 solved = factor.solve3(rows);
  return Eigen::Map<const Eigen::VectorXd>(solved.data(), stacked.size());
}

double strain_merit(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double merit = 0.0;
  for (const Spring& spring : springs) {
    const double strain = strain_error(x, spring);
    merit += strain * strain;
  }
  return merit;
}

// ------------------------------------------------------------------ the accelerated loop

StepReport accelerated_iterations(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& held, const Eigen::VectorXd& inv_mass,
                                  const PlainIteration& plain_iteration, const Merit& merit,
                                  const AcceleratedLoop& loop, const IterateCallback& on_iterate) {
  const bool tracked = loop.accelerated || loop.tolerance > 0.0 || on_iterate;
  StepReport report;
  Clock clock;
  auto record = [&](const IterationRecord& values) {
    if (!on_iterate) return false;
    const Timer timer;
    IterationRecord copy = values;
    copy.seconds = clock.seconds();
    const bool stop = on_iterate(copy, x);
    clock.excluded += timer.seconds();
    return stop;
  };
  // The plain iteration evaluates the merit only for the records, outside its time.
  auto evaluate = [&](const Eigen::Matrix3Xd& q) {
    const Timer timer;
    const double value = merit(q);
    if (!loop.accelerated && loop.tolerance == 0.0) clock.excluded += timer.seconds();
    return value;
  };
  double g = std::numeric_limits<double>::quiet_NaN();
  bool stopped = false;
  if (tracked) {
    g = evaluate(x);
    stopped = record({0, g, 0.0, 1.0, false, 0.0});
  }
  Schedule schedule{loop.rho, loop.delay};
  Eigen::Matrix3Xd previous = x, plain(3, x.cols()), next;
  for (int k = 1; k <= loop.iterations && !stopped; ++k) {
    plain_iteration(x, plain);
    IterationRecord values{k, 0.0, 0.0, 1.0, false, 0.0};
    double value = std::numeric_limits<double>::quiet_NaN();
    if (loop.accelerated) {
      values.omega = schedule.next(k);
      if (values.omega == 1.0 && loop.gamma == 1.0) {
        next = plain;  // the update would return q_hat bit for bit
        value = merit(next);
      } else {
        next = chebyshev_update(plain, x, previous, values.omega, loop.gamma);
        hold_pinned(next, held, inv_mass);
        value = merit(next);
        if (restart_needed(g, value, kRestartSlack)) {
          next = plain;
          value = merit(next);
          values.restarted = true;
          ++report.restarts;
          schedule.restart();
        }
      }
      previous.swap(x);
      x.swap(next);
    } else {
      x.swap(plain);
      if (tracked) value = evaluate(x);
    }
    report.iterations_done = k;
    if (!all_finite(x)) {
      report.problem = loop.name + ": non-finite positions after " + loop.unit + " " + std::to_string(k);
      return report;
    }
    if (!tracked) continue;
    values.objective = value;
    stopped = record(values);
    const bool small = loop.tolerance > 0.0 && decrease_below(g, value, loop.tolerance);
    g = value;
    if (small) {
      report.converged = true;
      break;
    }
  }
  report.objective = std::isnan(g) ? merit(x) : g;
  return report;
}

double estimate_plain_rho(Eigen::Matrix3Xd x, const PlainIteration& plain_iteration, int iterations, double scale) {
  if (iterations < 2) throw std::invalid_argument("estimate_rho: needs at least 2 iterations");
  std::vector<double> norms;
  Eigen::Matrix3Xd next(3, x.cols());
  for (int k = 0; k < iterations; ++k) {
    plain_iteration(x, next);
    const double length = (next - x).norm();
    if (!std::isfinite(length) || length <= 1e-12 * scale) break;  // round-off: no rate left to measure
    norms.push_back(length);
    x.swap(next);
  }
  if (norms.size() < 2) return 0.0;
  return estimate_spectral_radius(norms);
}

// ------------------------------------------------------------------ the solver

Solver::Solver(Eigen::VectorXd inv_mass, std::vector<Spring> springs, double dt)
    : inv_mass_(std::move(inv_mass)), springs_(std::move(springs)), dt_(dt) {
  for (const Spring& spring : springs_) {
    if (spring.i < 0 || spring.j < 0 || spring.i >= inv_mass_.size() || spring.j >= inv_mass_.size()) {
      throw std::invalid_argument("Solver: a spring joins a particle outside [0, " +
                                  std::to_string(inv_mass_.size()) + ")");
    }
  }
  if (!std::isfinite(dt_) || !(dt_ > 0.0)) throw std::invalid_argument("Solver: dt must be finite and > 0");
}

void Solver::require_pd() {
  if (problem_) return;
  problem_ = lab06::make_problem(inv_mass_, springs_, dt_);
  const Timer timer;
  if (!factor_.factor(lab06::system_matrix(*problem_))) {
    setup_problem_ = "the system matrix A = M/dt^2 + sum k S^T S is not positive definite to working precision";
  }
  factor_seconds_ += timer.seconds();
  newton_ = std::make_unique<lab06::Solver>(*problem_, lab06::Method::kNewton);
}

const lab06::Problem& Solver::problem() {
  require_pd();
  return *problem_;
}

int Solver::factorizations() const {
  return factor_.factorizations() + (newton_ ? newton_->factorizations() : 0);
}

StepReport Solver::step(Particles& particles, Method method, const Settings& settings,
                        const IterationCallback& on_iteration) {
  check(settings);
  if (particles.size() != inv_mass_.size() || particles.v.cols() != particles.size()) {
    throw std::invalid_argument("Solver::step: the particles do not match the solver's scene");
  }
  if (!minimises_objective(method)) return pbd(particles, method, settings, on_iteration);
  require_pd();
  const Timer timer;
  StepReport report;
  if (method == Method::kNewton) {
    lab06::StepSettings newton_settings;
    newton_settings.gravity = settings.gravity;
    newton_settings.iterations = settings.iterations;
    newton_settings.tolerance = settings.tolerance;
    const lab06::StepReport done = newton_->step(particles, newton_settings, [&](const lab06::IterationRecord& r) {
      IterationRecord record;
      record.iteration = r.iteration;
      record.objective = r.objective;
      record.seconds = r.seconds;
      return on_iteration ? on_iteration(record) : false;
    });
    report.iterations_done = done.iterations_done;
    report.objective = done.objective;
    report.converged = done.converged;
    report.failed_line_searches = done.failed_decreases;
    report.problem = done.problem;
    report.seconds = timer.seconds();
    return report;
  }
  const Eigen::Matrix3Xd y = lab06::predict(particles, settings.gravity, dt_);
  Eigen::Matrix3Xd x = y;
  report = minimise(x, y, method, settings, on_iteration);
  if (report.problem.empty() && !all_finite(x)) report.problem = std::string(method_name(method)) + ": non-finite positions";
  if (report.problem.empty()) {
    for (Eigen::Index p = 0; p < particles.size(); ++p) {
      particles.v.col(p) = inv_mass_[p] > 0.0 ? Eigen::Vector3d((x.col(p) - particles.x.col(p)) / dt_)
                                              : Eigen::Vector3d::Zero();
    }
    particles.x = x;
  }
  report.seconds = timer.seconds();
  return report;
}

StepReport Solver::minimise(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, Method method, const Settings& settings,
                            const IterationCallback& on_iteration) {
  check(settings);
  if (!minimises_objective(method) || method == Method::kNewton) {
    throw std::invalid_argument(std::string("Solver::minimise: not for ") + method_name(method));
  }
  require_pd();
  if (x.cols() != inv_mass_.size() || y.cols() != inv_mass_.size()) {
    throw std::invalid_argument("Solver::minimise: x and y need one column per particle");
  }
  if (!setup_problem_.empty()) {
    StepReport report;
    report.problem = setup_problem_;
    return report;
  }
  if (method == Method::kPdLbfgs) return lbfgs_pd(x, y, settings, on_iteration);
  // Plain PD (method kPd) or Chebyshev-accelerated PD on lab 06's objective g.
  const lab06::Problem& problem = *problem_;
  IterateCallback each = nullptr;
  if (on_iteration) {
    each = [&](const IterationRecord& record, const Eigen::Matrix3Xd& q) {
      IterationRecord copy = record;
      copy.max_strain = strain_stats(q, problem.springs).max;
      return on_iteration(copy);
    };
  }
  return accelerated_iterations(x, y, inv_mass_, pd_iteration(y),
                                [&](const Eigen::Matrix3Xd& q) { return lab06::objective(problem, q, y); },
                                {settings.iterations, settings.tolerance, method == Method::kPdChebyshev, settings.rho,
                                 settings.gamma, settings.delay, method_name(method), "iteration"},
                                each);
}

PlainIteration Solver::pd_iteration(const Eigen::Matrix3Xd& y) {
  return [this, &y](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain) {
    plain = lab06::global_step(*problem_, factor_, y, lab06::local_step(x, problem_->springs));
  };
}

// L-BFGS on PD's matrix (Liu et al. 2017): the direction of the two-loop
// recursion with H₀ = A⁻¹, then Armijo backtracking on g from the full step.
StepReport Solver::lbfgs_pd(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Settings& settings,
                            const IterationCallback& on_iteration) {
  const lab06::Problem& problem = *problem_;
  const MovableMap& map = problem.map;
  StepReport report;
  Clock clock;
  auto record = [&](int k, double value) {
    if (!on_iteration) return false;
    const Timer timer;
    const bool stop = on_iteration({k, value, strain_stats(x, problem.springs).max, 1.0, false, clock.seconds()});
    clock.excluded += timer.seconds();
    return stop;
  };
  const InverseApply initial = [&](const Eigen::VectorXd& v) { return apply_inverse(factor_, v); };
  // x + alpha·direction into `trial`, which keeps its storage from one try
  // and one iteration to the next (no allocation inside the loop).
  Eigen::Matrix3Xd trial = x;
  auto move_to_trial = [&](const Eigen::VectorXd& direction, double alpha) {
    trial = x;
    for (int u = 0; u < map.unknowns(); ++u) {
      trial.col(map.particle_of[static_cast<std::size_t>(u)]) += alpha * direction.segment<3>(3 * u);
    }
  };
  // The pairs, oldest first, handed to lbfgs_direction as they are (no copy
  // per iteration). Once m are kept, the oldest pair's vectors are rotated to
  // the back and overwritten by the newest: the same values, no allocation.
  std::vector<CurvaturePair> history;
  history.reserve(static_cast<std::size_t>(settings.history));
  double g = lab06::objective(problem, x, y);
  Eigen::VectorXd gradient = lab06::newton_gradient(problem, x, y);
  bool stopped = record(0, g);
  for (int k = 1; k <= settings.iterations && !stopped; ++k) {
    if (!gradient.allFinite()) {
      report.problem = "pd-lbfgs iteration " + std::to_string(k) + ": the gradient is not finite";
      break;
    }
    Eigen::VectorXd direction = lbfgs_direction(gradient, history, initial);
    double slope = gradient.dot(direction);
    if (!(slope < 0.0) || !direction.allFinite()) {  // not a descent: forget the history, take PD's direction
      history.clear();
      direction = -initial(gradient);
      slope = gradient.dot(direction);
      if (slope < 0.0) ++report.descent_fallbacks;  // PD's direction descends where the recursion's did not
    }
    if (!(slope < 0.0)) {  // ∇g = 0 to the last bit
      report.converged = true;
      break;
    }
    double alpha = 1.0;
    double value = 0.0;
    Eigen::VectorXd next_gradient;
    bool polish = !(-0.5 * slope > 8.0 * kEpsilon * std::abs(g));
    if (!polish) {
      bool accepted = false;
      double full_step_value = 0.0;
      for (int halving = 0; halving < 60; ++halving, alpha *= 0.5) {
        move_to_trial(direction, alpha);
        value = lab06::objective(problem, trial, y);
        if (halving == 0) full_step_value = value;
        if (value <= g + 1e-4 * alpha * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        if (!(std::abs(full_step_value - g) <= 16.0 * kEpsilon * std::abs(g))) {
          ++report.failed_line_searches;
          break;
        }
        polish = true;  // within round-off of g: the objective cannot judge the step
      }
    }
    if (polish) {
      // The predicted decrease is at the round-off of g: the objective cannot
      // tell where the minimum is any more, the gradient can. Full steps while
      // they shrink the gradient and are above the round-off of x.
      alpha = 1.0;
      const double length = direction.cwiseAbs().maxCoeff();
      if (length <= 64.0 * kEpsilon * x.cwiseAbs().maxCoeff()) {
        report.converged = true;
        break;
      }
      move_to_trial(direction, 1.0);
      value = lab06::objective(problem, trial, y);
      next_gradient = lab06::newton_gradient(problem, trial, y);
      if (!(next_gradient.norm() < gradient.norm())) {
        report.converged = true;
        break;
      }
    } else {
      next_gradient = lab06::newton_gradient(problem, trial, y);
    }
    if (settings.history > 0) {
      if (static_cast<int>(history.size()) < settings.history) {
        history.emplace_back();
      } else {
        std::rotate(history.begin(), history.begin() + 1, history.end());
      }
      history.back().s = alpha * direction;
      history.back().y = next_gradient - gradient;
    }
    x.swap(trial);
    gradient.swap(next_gradient);
    const double previous = g;
    g = value;
    report.iterations_done = k;
    stopped = record(k, g);
    if (settings.tolerance > 0.0 && decrease_below(previous, g, settings.tolerance)) {
      report.converged = true;
      break;
    }
  }
  report.objective = g;
  return report;
}

// PBD (lab 04's step) with the sweeps of lab 02 or lab 03, and Wang's
// Chebyshev acceleration of the Jacobi sweeps.
StepReport Solver::pbd(Particles& particles, Method method, const Settings& settings,
                       const IterationCallback& on_iteration) {
  const Timer timer;
  Eigen::Matrix3Xd p = pbd_prediction(particles, settings.gravity);
  const Eigen::Matrix3Xd held = p;
  IterateCallback each = nullptr;
  if (on_iteration) {
    each = [&](const IterationRecord& record, const Eigen::Matrix3Xd& q) {
      IterationRecord copy = record;
      copy.max_strain = strain_stats(q, springs_).max;
      return on_iteration(copy);
    };
  }
  // PBD has no objective, hence no tolerance: the merit judges the restarts alone.
  StepReport report = accelerated_iterations(
      p, held, inv_mass_, pbd_iteration(method), [&](const Eigen::Matrix3Xd& q) { return strain_merit(q, springs_); },
      {settings.iterations, 0.0, method == Method::kJacobiChebyshev, settings.rho, settings.gamma, settings.delay,
       method_name(method), "sweep"},
      each);
  if (!report.problem.empty()) return report;
  particles.v = (p - particles.x) / dt_;
  particles.x = p;
  report.seconds = timer.seconds();
  return report;
}

double Solver::estimate_rho(const Particles& start, Method method, const Settings& settings, int iterations) {
  if (iterations < 2) throw std::invalid_argument("estimate_rho: needs at least 2 iterations");
  const double scale = std::max(start.x.cwiseAbs().maxCoeff(), 1e-300);
  if (minimises_objective(method)) {
    require_pd();
    if (!setup_problem_.empty()) return 0.0;
    const Eigen::Matrix3Xd y = lab06::predict(start, settings.gravity, dt_);
    return estimate_plain_rho(y, pd_iteration(y), iterations, scale);
  }
  return estimate_plain_rho(pbd_prediction(start, settings.gravity), pbd_iteration(Method::kJacobi), iterations, scale);
}

// lab 04's prediction, operation for operation (a plain run is its step bit for bit).
Eigen::Matrix3Xd Solver::pbd_prediction(const Particles& particles, const Eigen::Vector3d& gravity) const {
  Eigen::Matrix3Xd p = particles.x;
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    if (inv_mass_[i] > 0.0) {
      const Eigen::Vector3d velocity = particles.v.col(i) + dt_ * gravity;
      p.col(i) += dt_ * velocity;
    }
  }
  return p;
}

PlainIteration Solver::pbd_iteration(Method method) {
  if (!constraints_) constraints_ = lab04::make_constraint_set(inv_mass_.size(), springs_);
  const lab04::ConstraintSet& constraints = *constraints_;
  if (method == Method::kGaussSeidel) {
    return [this, &constraints](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain) {
      plain = x;
      lab02::gauss_seidel_sweep(plain, inv_mass_, springs_, constraints.order);
    };
  }
  return [this, &constraints](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain) {
    lab03::jacobi_sweep(x, plain, inv_mass_, springs_, constraints.incidence, 1.0, lab03::Averaging::kByCount);
  };
}

// ------------------------------------------------------------------ a run

namespace {

// PBD treats springs as hard constraints: their energy is not the scene's.
double total_energy(const Particles& particles, const std::vector<Spring>& springs, const Eigen::Vector3d& gravity,
                    bool elastic) {
  const double motion = kinetic_energy(particles) + potential_energy(particles, gravity);
  return elastic ? motion + lab06::spring_energy(particles.x, springs) : motion;
}

}  // namespace

RunResult run_steps(Particles& particles, Solver& solver, Method method, const Settings& settings, int steps,
                    const StepCallback& on_step, const RunIterationCallback& on_iteration, const FrameOutput& output) {
  if (steps < 0) throw std::invalid_argument("run_steps: steps must be >= 0");
  const std::vector<Spring>& springs = solver.springs();
  const bool elastic = minimises_objective(method);
  RunResult result;
  StepRecord record;
  StepReport report;
  auto step = [&](int s) {
    IterationCallback each = nullptr;
    if (on_iteration) {
      each = [&](const IterationRecord& iteration) {
        on_iteration(s, iteration);
        return false;
      };
    }
    report = solver.step(particles, method, settings, each);
    result.iterations_done += report.iterations_done;
    result.restarts += report.restarts;
    result.failed_line_searches += report.failed_line_searches;
    result.descent_fallbacks += report.descent_fallbacks;
    return StepVerdict{report.problem, true, report.seconds};
  };
  auto measured = [&](int s, double) {
    record = StepRecord{};
    record.step = s;
    if (s > 0) record.report = report;
    record.strain = strain_stats(particles.x, springs);
    record.total_energy = total_energy(particles, springs, settings.gravity, elastic);
    return FrameMeasure{record.strain, record.total_energy, {},
                        {record.report.objective, static_cast<long long>(record.report.iterations_done),
                         static_cast<long long>(record.report.converged ? 1 : 0),
                         static_cast<long long>(record.report.restarts),
                         static_cast<long long>(record.report.failed_line_searches),
                         static_cast<long long>(record.report.descent_fallbacks), record.report.seconds,
                         record.strain.max, record.strain.rms, record.total_energy},
                        {}};
  };
  const double scale = energy_scale(particles, settings.gravity, solver.dt()) +
                       (elastic ? lab06::spring_energy(particles.x, springs) : 0.0);
  FrameOutput with_index = output;
  with_index.index_column = "step";
  const FrameLoopResult run = run_frame_loop(particles, step, measured, frame_plan(steps, solver.dt(), scale),
                                             with_index, record_hook(record, on_step));
  copy_outcome(run, result, result.steps_done, result.problem_step);
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  return result;
}

std::vector<std::string> step_columns() {
  return {"objective", "iterations", "converged", "restarts", "failed_line_searches", "descent_fallbacks", "seconds",
          "max_strain", "rms_strain", "total_energy"};
}

}  // namespace cl::lab11
