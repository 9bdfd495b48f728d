// Lab 06 — given code: the step by projective dynamics or Newton, and the run loop.
#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/timer.h"

namespace cl::lab06 {

namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// The tolerance rule of StepSettings: the relative decrease fell below tol
// (an increase or no change counts as "below").
bool decrease_below(double previous, double current, double tolerance) {
  if (!(previous > 0.0)) return true;
  return previous - current < tolerance * previous;
}

// The unit direction of x_i − x_j and its length; (1, 0, 0) for coincident ends.
double direction(const Eigen::Matrix3Xd& x, const Spring& spring, Eigen::Vector3d& unit) {
  const Eigen::Vector3d edge = x.col(spring.i) - x.col(spring.j);
  const double length = edge.norm();
  unit = length > 0.0 ? Eigen::Vector3d(edge / length) : Eigen::Vector3d::UnitX();
  return length;
}

}  // namespace

const char* method_name(Method method) { return method == Method::kNewton ? "newton" : "pd"; }

Eigen::Matrix3Xd predict(const Particles& particles, const Eigen::Vector3d& gravity, double dt) {
  Eigen::Matrix3Xd y = particles.x;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) y.col(p) += dt * particles.v.col(p) + (dt * dt) * gravity;
  }
  return y;
}

double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double energy = 0.0;
  for (const Spring& spring : springs) {
    const double stretch = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  return energy;
}

// ------------------------------------------------------------------ Newton's pieces

Eigen::VectorXd newton_gradient(const Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  const MovableMap& map = problem.map;
  const double inv_dt2 = 1.0 / (problem.dt * problem.dt);
  Eigen::VectorXd gradient(3 * map.unknowns());
  for (int u = 0; u < map.unknowns(); ++u) {
    const int p = map.particle_of[static_cast<std::size_t>(u)];
    gradient.segment<3>(3 * u) = (inv_dt2 / problem.inv_mass[p]) * (x.col(p) - y.col(p));
  }
  for (const Spring& spring : problem.springs) {
    Eigen::Vector3d unit;
    const double length = direction(x, spring, unit);
    const Eigen::Vector3d force = spring.stiffness * (length - spring.rest_length) * unit;  // ∂E_e/∂x_i
    const int a = map.unknown_of[static_cast<std::size_t>(spring.i)];
    const int b = map.unknown_of[static_cast<std::size_t>(spring.j)];
    if (a >= 0) gradient.segment<3>(3 * a) += force;
    if (b >= 0) gradient.segment<3>(3 * b) -= force;
  }
  return gradient;
}

namespace {

// Spring e's 3×3 block of the Hessian at x: k [n nᵀ + across (I − n nᵀ)].
Eigen::Matrix3d spring_block(const Eigen::Matrix3Xd& x, const Spring& spring, bool clamp) {
  Eigen::Vector3d unit;
  const double length = direction(x, spring, unit);
  // Across the spring: 1 − L/l, negative when it is compressed; clamped to 0.
  double across = 1.0;
  if (spring.rest_length > 0.0 && length > 0.0) {
    across = 1.0 - spring.rest_length / length;
    if (clamp) across = std::max(0.0, across);
  } else if (spring.rest_length > 0.0) {
    across = 0.0;
  }
  const Eigen::Matrix3d along = unit * unit.transpose();
  return spring.stiffness * (along + across * (Eigen::Matrix3d::Identity() - along));
}

}  // namespace

HessianAssembly::HessianAssembly(const Problem& problem) : blocks_(problem.map, problem.springs) {}

const SparseMatrix& HessianAssembly::update(const Problem& problem, const Eigen::Matrix3Xd& x, bool clamp) {
  const MovableMap& map = problem.map;
  if (blocks_.rows() != 3 * static_cast<Eigen::Index>(map.unknowns()) ||
      blocks_.springs() != problem.springs.size()) {
    throw std::invalid_argument("HessianAssembly::update: the problem is not the one the pattern was made for");
  }
  const double inv_dt2 = 1.0 / (problem.dt * problem.dt);
  blocks_.set_zero();
  for (int u = 0; u < map.unknowns(); ++u) {
    blocks_.add_diagonal(u, inv_dt2 / problem.inv_mass[map.particle_of[static_cast<std::size_t>(u)]]);
  }
  for (std::size_t e = 0; e < problem.springs.size(); ++e) {
    if (!blocks_.has_block(e)) continue;  // both ends pinned
    blocks_.add_spring(e, spring_block(x, problem.springs[e], clamp));
  }
  return blocks_.matrix();
}

SparseMatrix newton_hessian(const Problem& problem, const Eigen::Matrix3Xd& x, bool clamp) {
  HessianAssembly assembly(problem);
  return assembly.update(problem, x, clamp);
}

// ------------------------------------------------------------------ the solver

Solver::Solver(Problem problem, Method method) : problem_(std::move(problem)), method_(method) {
  if (method_ != Method::kProjectiveDynamics) return;
  const SparseMatrix a = system_matrix(problem_);
  const Timer timer;
  const bool ok = factor_.factor(a);
  factor_seconds_ += timer.seconds();
  ++factorizations_;
  if (!ok) setup_problem_ = "the system matrix A = M/dt^2 + sum k S^T S is not positive definite to working precision";
}

const char* Solver::linear_solver() const {
  return backend_name(method_ == Method::kNewton ? hessian_factor_.backend() : factor_.backend());
}

StepReport Solver::step(Particles& particles, const StepSettings& settings, const IterationCallback& on_iteration) {
  if (settings.iterations < 0 || !(settings.tolerance >= 0.0) || !std::isfinite(settings.tolerance)) {
    throw std::invalid_argument("Solver::step: needs iterations >= 0 and a finite tolerance >= 0");
  }
  if (particles.size() != problem_.inv_mass.size() || particles.v.cols() != particles.size()) {
    throw std::invalid_argument("Solver::step: the particles do not match the problem (" +
                                std::to_string(particles.size()) + " particles, the problem has " +
                                std::to_string(problem_.inv_mass.size()) + ")");
  }
  const Timer timer;
  StepReport report;
  if (!setup_problem_.empty()) {
    report.problem = setup_problem_;
    return report;
  }
  const Eigen::Matrix3Xd y = predict(particles, settings.gravity, problem_.dt);
  Eigen::Matrix3Xd x = y;
  report = method_ == Method::kProjectiveDynamics ? projective_dynamics(x, y, settings, on_iteration)
                                                  : newton(x, y, settings, on_iteration);
  if (report.problem.empty() && !all_finite(x)) {
    report.problem = std::string(method_name(method_)) + " produced non-finite positions";
  }
  if (report.problem.empty()) {
    for (Eigen::Index p = 0; p < particles.size(); ++p) {
      particles.v.col(p) = particles.inv_mass[p] > 0.0 ? Eigen::Vector3d((x.col(p) - particles.x.col(p)) / problem_.dt)
                                                       : Eigen::Vector3d::Zero();
    }
    particles.x = x;
  }
  report.seconds = timer.seconds();
  return report;
}

StepReport Solver::projective_dynamics(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const StepSettings& settings,
                                       const IterationCallback& on_iteration) const {
  StepReport report;
  const Timer clock;
  double excluded = 0.0;  // time spent only for the records
  const bool tracked = settings.tolerance > 0.0;
  auto evaluate = [&]() {
    const Timer timer;
    const double value = objective(problem_, x, y);
    if (!tracked) excluded += timer.seconds();
    return value;
  };
  auto record = [&](int iteration, double value) {
    if (!on_iteration) return false;
    const Timer timer;
    const bool stop = on_iteration({iteration, value, clock.seconds() - excluded, factorizations_, &x});
    excluded += timer.seconds();
    return stop;
  };
  double g = std::numeric_limits<double>::quiet_NaN();
  bool stopped = false;
  if (tracked || on_iteration) {
    g = evaluate();
    stopped = record(0, g);
  }
  for (int k = 1; k <= settings.iterations && !stopped; ++k) {
    const Eigen::Matrix3Xd d = local_step(x, problem_.springs);
    x = global_step(problem_, factor_, y, d);
    report.iterations_done = k;
    if (!all_finite(x)) {
      report.problem = "projective dynamics: non-finite positions after iteration " + std::to_string(k);
      return report;
    }
    if (!tracked && !on_iteration) continue;
    const double next = evaluate();
    stopped = record(k, next);
    const bool small = tracked && decrease_below(g, next, settings.tolerance);
    g = next;
    if (small) {
      report.converged = true;
      break;
    }
  }
  report.objective = std::isnan(g) ? objective(problem_, x, y) : g;
  return report;
}

StepReport Solver::newton(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const StepSettings& settings,
                          const IterationCallback& on_iteration) {
  StepReport report;
  const MovableMap& map = problem_.map;
  const Timer clock;
  double excluded = 0.0;
  auto record = [&](int iteration, double value) {
    if (!on_iteration) return false;
    const Timer timer;
    const bool stop = on_iteration({iteration, value, clock.seconds() - excluded, factorizations_, &x});
    excluded += timer.seconds();
    return stop;
  };
  auto moved = [&](const Eigen::VectorXd& step, double alpha) {
    Eigen::Matrix3Xd trial = x;
    for (int u = 0; u < map.unknowns(); ++u) {
      trial.col(map.particle_of[static_cast<std::size_t>(u)]) += alpha * step.segment<3>(3 * u);
    }
    return trial;
  };
  double g = objective(problem_, x, y);  // the line search needs it
  bool stopped = record(0, g);
  double last_polish = std::numeric_limits<double>::infinity();  // the last round-off-regime step
  for (int k = 1; k <= settings.iterations && !stopped; ++k) {
    const std::string where = "newton iteration " + std::to_string(k) + ": ";
    const Eigen::VectorXd gradient = newton_gradient(problem_, x, y);
    if (!gradient.allFinite()) {
      report.problem = where + "the gradient is not finite";
      break;
    }
    if (hessian_.empty()) hessian_ = HessianAssembly(problem_);
    const SparseMatrix& hessian = hessian_.update(problem_, x);
    const Timer timer;
    const bool ok = hessian_factor_.refactor(hessian);
    factor_seconds_ += timer.seconds();
    ++factorizations_;
    if (!ok) {
      report.problem = where + "the clamped Hessian is not positive definite to working precision";
      break;
    }
    const Eigen::VectorXd step = hessian_factor_.solve(-gradient);
    const double slope = gradient.dot(step);  // < 0 for a descent direction
    if (!step.allFinite() || !std::isfinite(slope)) {
      report.problem = where + "the Newton step is not finite";
      break;
    }
    // A predicted decrease −slope/2 at the round-off of g: the objective can no
    // longer tell where the minimum is (x is only known to about √ε there),
    // but the gradient can. Take full steps while they keep shrinking (at
    // least halving) and stop once they are down to the round-off of x.
    if (!(-0.5 * slope > 8.0 * kEpsilon * std::abs(g))) {
      const double length = step.cwiseAbs().maxCoeff();
      const double previous = g;
      x = moved(step, 1.0);
      g = objective(problem_, x, y);
      report.iterations_done = k;
      report.converged = true;  // in the objective, at least
      stopped = record(k, g);
      if (length <= 64.0 * kEpsilon * x.cwiseAbs().maxCoeff() || length > 0.5 * last_polish ||
          (settings.tolerance > 0.0 && decrease_below(previous, g, settings.tolerance))) {
        break;
      }
      last_polish = length;
      continue;
    }
    // Backtracking (Armijo) from the full step.
    double alpha = 1.0;
    bool accepted = false;
    double full_step_value = 0.0;
    Eigen::Matrix3Xd trial;
    double value = 0.0;
    for (int halving = 0; halving < 60; ++halving, alpha *= 0.5) {
      trial = moved(step, alpha);
      value = objective(problem_, trial, y);
      if (halving == 0) full_step_value = value;
      if (value <= g + 1e-4 * alpha * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      // Within round-off of g the objective cannot tell better from worse:
      // converged, as above. Otherwise the step failed: report it.
      if (std::abs(full_step_value - g) <= 16.0 * kEpsilon * std::abs(g)) {
        x = moved(step, 1.0);
        g = full_step_value;
        report.iterations_done = k;
        report.converged = true;
        record(k, g);
      } else {
        ++report.failed_decreases;
      }
      break;
    }
    x = trial;
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

// ------------------------------------------------------------------ a run

namespace {

StepRecord measure(int step, double time, const Particles& particles, const Problem& problem,
                   const Eigen::Vector3d& gravity) {
  StepRecord record;
  record.step = step;
  record.time = time;
  record.strain = strain_stats(particles.x, problem.springs);
  record.kinetic = kinetic_energy(particles);
  record.potential = potential_energy(particles, gravity);
  record.elastic = spring_energy(particles.x, problem.springs);
  return record;
}

}  // namespace

RunResult run_steps(Particles& particles, Solver& solver, const StepSettings& settings, int steps,
                    const StepCallback& on_step, const FrameOutput& output) {
  if (steps < 0) throw std::invalid_argument("run_steps: steps must be >= 0");
  const Problem& problem = solver.problem();
  RunResult result;

  StepRecord record;
  StepReport report;
  auto step = [&](int) {
    report = solver.step(particles, settings);
    result.iterations_done += report.iterations_done;
    result.failed_decreases += report.failed_decreases;
    result.objective = report.objective;
    return StepVerdict{report.problem, true, report.seconds};
  };
  auto measured = [&](int s, double) {
    record = measure(s, s * problem.dt, particles, problem, settings.gravity);
    if (s > 0) record.report = report;
    const double total = record.kinetic + record.potential + record.elastic;
    return FrameMeasure{record.strain, total, {},
                        {record.report.objective, static_cast<long long>(record.report.iterations_done),
                         static_cast<long long>(record.report.converged ? 1 : 0),
                         static_cast<long long>(record.report.failed_decreases), record.report.seconds,
                         record.strain.max, record.strain.rms, record.kinetic, record.potential, record.elastic,
                         total},
                        {}};
  };
  // The scale needs the initial elastic energy, which the loop measures first:
  // measure frame 0 once here for it (measuring changes nothing).
  const StepRecord start = measure(0, 0.0, particles, problem, settings.gravity);
  const FramePlan loop =
      frame_plan(steps, problem.dt, energy_scale(particles, settings.gravity, problem.dt) + start.elastic);
  FrameOutput with_index = output;
  with_index.index_column = "step";
  const FrameLoopResult run = run_frame_loop(particles, step, measured, loop, with_index, record_hook(record, on_step));

  copy_outcome(run, result, result.steps_done, result.problem_step);
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  result.energy_scale = loop.energy_scale;
  return result;
}

std::vector<std::string> step_columns() {
  return {"objective", "iterations", "converged", "failed_decreases", "seconds", "max_strain", "rms_strain",
          "kinetic", "potential", "elastic", "total_energy"};
}

}  // namespace cl::lab06
