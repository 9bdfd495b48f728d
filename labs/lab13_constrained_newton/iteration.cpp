// Lab 13 — given code: the constrained Newton iteration, its safeguard, the run.
#include "iteration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "../lab06_projective_dynamics/simulation.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/timer.h"
#include "stable_step.h"

namespace cl::lab13 {

namespace {

// The part δ of the compressed springs' K_g that a refused matrix drops:
// first 0.01, then ×4 (0.04, 0.16, 0.64) up to 1, all of it (lab 09's
// kDrop, whose matrix is M plus a positive semidefinite one).
constexpr double kFirstDropped = 1e-2;


void check(const Settings& settings) {
  if (settings.iterations < 0) throw std::invalid_argument("iterations must be >= 0");
  if (!std::isfinite(settings.tolerance) || settings.tolerance < 0.0) {
    throw std::invalid_argument("tolerance must be finite and >= 0");
  }
  if (settings.max_backtracks < 0) throw std::invalid_argument("max_backtracks must be >= 0");
  if (!settings.gravity.allFinite()) throw std::invalid_argument("gravity must be finite");
}

}  // namespace

const char* start_name(Start start) { return start == Start::kPrediction ? "prediction" : "x"; }

Start start_from_name(const std::string& name) {
  if (name == "x") return Start::kPositions;
  if (name == "prediction") return Start::kPrediction;
  throw std::invalid_argument("unknown start '" + name + "' (x or prediction)");
}

const char* warm_name(Warm warm) { return warm == Warm::kZero ? "zero" : "forces"; }

Warm warm_from_name(const std::string& name) {
  if (name == "forces") return Warm::kForces;
  if (name == "zero") return Warm::kZero;
  throw std::invalid_argument("unknown warm start '" + name + "' (forces or zero)");
}

double length_scale(const std::vector<Spring>& springs) {
  double sum = 0.0;
  for (const Spring& s : springs) sum += s.rest_length;
  return sum > 0.0 ? sum / static_cast<double>(springs.size()) : 1.0;
}

Solver::Solver(const Eigen::VectorXd& inv_mass, const std::vector<Spring>& springs, double dt)
    : inv_mass_(inv_mass), map_(make_movable_map(inv_mass)), dt_(dt) {
  if (!std::isfinite(dt) || !(dt > 0.0)) throw std::invalid_argument("dt must be finite and > 0");
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    if (s.i < 0 || s.j < 0 || s.i >= inv_mass.size() || s.j >= inv_mass.size()) {
      throw std::invalid_argument("springs[" + std::to_string(e) + "] has an index out of range");
    }
    if (inv_mass[s.i] > 0.0 || inv_mass[s.j] > 0.0) springs_.push_back(s);
  }
  compliance_ = lab07::compliance_of(springs_);
  weights_ = merit_weights(springs_, inv_mass_, compliance_, dt_);
  length_scale_ = length_scale(springs_);
  if (!springs_.empty() && all_compliant()) eliminated_ = SpringBlockMatrix(map_, springs_);
}

bool Solver::all_compliant() const {
  return springs_.empty() || (compliance_.size() != 0 && (compliance_.array() > 0.0).all());
}

StepReport Solver::step(Particles& particles, const Settings& settings, const IterationCallback& on_iteration) {
  check(settings);
  if (particles.size() != inv_mass_.size() || particles.v.cols() != particles.size()) {
    throw std::invalid_argument("Solver::step: the particles do not match the solver's scene");
  }
  const Timer timer;
  const Eigen::Matrix3Xd y = lab06::predict(particles, settings.gravity, dt_);
  Eigen::Matrix3Xd x = settings.start == Start::kPrediction ? y : particles.x;
  Eigen::VectorXd lambda = warm_start(particles.x, springs_, previous_lambda_, settings.warm);
  StepReport report = iterate(x, lambda, y, settings, on_iteration);
  if (report.problem.empty()) {
    for (Eigen::Index p = 0; p < particles.size(); ++p) {
      particles.v.col(p) = inv_mass_[p] > 0.0 ? Eigen::Vector3d((x.col(p) - particles.x.col(p)) / dt_)
                                              : Eigen::Vector3d::Zero();
    }
    particles.x = x;
    previous_lambda_ = std::move(lambda);
  }
  report.seconds = timer.seconds();
  return report;
}

lab07::StepSolution Solver::schur_solve(const Eigen::Matrix3Xd& x, const Eigen::VectorXd& velocity,
                                       const Eigen::VectorXd& lambda, const Eigen::Vector3d& gravity,
                                       lab09::Compression compression, double dropped, Eigen::VectorXd& rhs) const {
  // Lab 09's eliminated system (geometric_stiffness.h) at x, per spring e
  // with n = (x_i − x_j)/ℓ and s = 1/c_e: the mass on the diagonal, and the block
  //     Δt² [ s n nᵀ − (λ_e/ℓ)(I − n nᵀ) ]       (Δt² Jᵀ C⁻¹ J − Δt² K_g)
  // at (i,i), (j,j) and negated at (i,j), (j,i); the right-hand side
  // M(v̂ + Δt g) − Δt Jᵀ C⁻¹ φ. Coincident ends have no direction: an empty
  // row of J and no K_g (lab 07's and lab 09's rule), so no block. With kKeep
  // a compressed spring's K_g block is scaled by 1 − dropped (iterate()'s
  // correction); the right-hand side does not depend on it.
  const double dt2 = dt_ * dt_;
  const std::size_t m = springs_.size();
  Eigen::Matrix3Xd units(3, static_cast<Eigen::Index>(m));
  Eigen::VectorXd phi(static_cast<Eigen::Index>(m));
  rhs.resize(3 * map_.unknowns());
  eliminated_.set_zero();
  for (int u = 0; u < map_.unknowns(); ++u) {
    const double w = inv_mass_[map_.particle_of[static_cast<std::size_t>(u)]];
    eliminated_.add_diagonal(u, 1.0 / w);
    rhs.segment<3>(3 * u) = (velocity.segment<3>(3 * u) + dt_ * gravity) / w;
  }
  for (std::size_t e = 0; e < m; ++e) {
    const Spring& s = springs_[e];
    const auto index = static_cast<Eigen::Index>(e);
    const Eigen::Vector3d d = x.col(s.i) - x.col(s.j);
    const double length = d.norm();
    phi[index] = length - s.rest_length;
    if (!(length > 0.0)) {
      units.col(index).setZero();
      continue;
    }
    const Eigen::Vector3d n = d / length;
    units.col(index) = n;
    const double stiffness = 1.0 / compliance_[index];
    const Eigen::Matrix3d along = n * n.transpose();
    Eigen::Matrix3d block = (dt2 * stiffness) * along;
    double force = lambda[index];
    if (force > 0.0) force *= compression == lab09::Compression::kDrop ? 0.0 : 1.0 - dropped;
    if (force != 0.0) block -= (dt2 * force / length) * (Eigen::Matrix3d::Identity() - along);
    eliminated_.add_spring(e, block);
    const Eigen::Vector3d pull = (dt_ * stiffness * phi[index]) * n;
    const int a = map_.unknown_of[static_cast<std::size_t>(s.i)];
    const int b = map_.unknown_of[static_cast<std::size_t>(s.j)];
    if (a >= 0) rhs.segment<3>(3 * a) -= pull;
    if (b >= 0) rhs.segment<3>(3 * b) += pull;
  }
  lab07::StepSolution solution;
  if (!factor_.refactor(eliminated_.matrix())) {
    solution.problem = "the eliminated matrix M - dt^2 K_g + dt^2 J^T C^-1 J is not positive definite";
    // With springs dropped from K_g it is M plus a positive semidefinite
    // matrix: only round-off refuses it, when Δt² k outweighs a mass by more
    // than a double resolves. Say so in terms of Δt.
    const bool all_dropped = compression == lab09::Compression::kDrop || dropped == 1.0;
    double ratio = 0.0;
    for (std::size_t e = 0; e < m; ++e) {
      const Spring& s = springs_[e];
      ratio = std::max(ratio, dt2 / compliance_[static_cast<Eigen::Index>(e)] * (inv_mass_[s.i] + inv_mass_[s.j]));
    }
    double lightest = std::numeric_limits<double>::infinity(), heaviest = 0.0;
    for (const int p : map_.particle_of) {
      lightest = std::min(lightest, 1.0 / inv_mass_[p]);
      heaviest = std::max(heaviest, 1.0 / inv_mass_[p]);
    }
    char text[240];
    if (all_dropped && ratio > 1e12) {
      std::snprintf(text, sizeof text,
                    " to working precision: at dt = %.3g s, dt^2 k / m reaches %.2g, more than a double resolves; "
                    "use a smaller dt (--dt)",
                    dt_, ratio);
      solution.problem += text;
    } else if (all_dropped && heaviest > 1e12 * lightest) {
      std::snprintf(text, sizeof text,
                    " to working precision: the scene's masses span %.2g kg to %.2g kg, more than a double resolves "
                    "in one matrix; bring them within 1e12 of each other",
                    lightest, heaviest);
      solution.problem += text;
    }
    return solution;
  }
  solution.velocity = factor_.solve(rhs);
  // λ = −C⁻¹(φ + Δt J v_new), J v_new per spring: n·(v_i − v_j), a pinned end's v = 0.
  solution.lambda.resize(static_cast<Eigen::Index>(m));
  for (std::size_t e = 0; e < m; ++e) {
    const Spring& s = springs_[e];
    const auto index = static_cast<Eigen::Index>(e);
    const int a = map_.unknown_of[static_cast<std::size_t>(s.i)];
    const int b = map_.unknown_of[static_cast<std::size_t>(s.j)];
    double rate = 0.0;
    if (a >= 0) rate += units.col(index).dot(solution.velocity.segment<3>(3 * a));
    if (b >= 0) rate -= units.col(index).dot(solution.velocity.segment<3>(3 * b));
    solution.lambda[index] = -(phi[index] + dt_ * rate) / compliance_[index];
  }
  solution.ok = solution.velocity.allFinite() && solution.lambda.allFinite();
  if (!solution.ok) solution.problem = "the Schur solve is not finite";
  return solution;
}

std::string Solver::hard_set_problem(const Eigen::Matrix3Xd& x, const std::string& problem) const {
  if (problem.find("singular") == std::string::npos) return problem;
  // Say what in the scene makes lab 07's KKT matrix singular: a spring given
  // twice, a spring whose ends coincide (no direction), or more hard
  // constraints than the movable coordinates can satisfy independently.
  std::string what;
  int hard = 0;
  for (std::size_t e = 0; e < springs_.size() && what.empty(); ++e) {
    const Spring& s = springs_[e];
    const bool is_hard = compliance_.size() == 0 || compliance_[static_cast<Eigen::Index>(e)] == 0.0;
    if (!is_hard) continue;
    ++hard;
    if (!((x.col(s.i) - x.col(s.j)).norm() > 0.0)) {
      what = "hard spring " + std::to_string(e) + " has coincident ends (particles " + std::to_string(s.i) + " and " +
             std::to_string(s.j) + "): its constraint has no direction";
    }
    for (std::size_t f = 0; f < e && what.empty(); ++f) {
      const Spring& t = springs_[f];
      if ((t.i == s.i && t.j == s.j) || (t.i == s.j && t.j == s.i)) {
        what = "hard springs " + std::to_string(f) + " and " + std::to_string(e) + " join the same particles (" +
               std::to_string(s.i) + ", " + std::to_string(s.j) + ")";
      }
    }
  }
  if (what.empty()) {
    hard = 0;
    for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(springs_.size()); ++e) {
      if (compliance_.size() == 0 || compliance_[e] == 0.0) ++hard;
    }
    what = "its " + std::to_string(hard) + " hard springs on " + std::to_string(3 * map_.unknowns()) +
           " movable coordinates are a redundant set (some constraint is implied by others, or a taut set leaves "
           "no motion)";
  }
  return "the hard constraints are redundant or singular here, so the step and its forces are not unique: " + what +
         ". Give the springs a finite stiffness (--stiffness, e.g. 1e9) or remove the redundant ones (lab 07's "
         "README.md, redundant constraints). [" + problem + "]";
}

double Solver::objective(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) const {
  double inertia = 0.0;
  for (const int p : map_.particle_of) inertia += (x.col(p) - y.col(p)).squaredNorm() / inv_mass_[p];
  double elastic = 0.0;
  for (std::size_t e = 0; e < springs_.size(); ++e) {
    const Spring& s = springs_[e];
    const double phi = (x.col(s.i) - x.col(s.j)).norm() - s.rest_length;
    elastic += phi * phi / compliance_[static_cast<Eigen::Index>(e)];
  }
  return 0.5 * inertia / (dt_ * dt_) + 0.5 * elastic;
}

bool Solver::descend_on_g(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Eigen::VectorXd& dx,
                          double slope, int max_backtracks, Eigen::Matrix3Xd& trial, double& alpha,
                          int& backtracks) const {
  if (!(slope < 0.0)) return false;
  const double before = objective(x, y);
  // At g's round-off (a predicted decrease of a few ulps of g) g cannot
  // judge a step, and the iterate is as good as g can tell: no fallback (ψ,
  // which does not lose the springs' forces to round-off as g's gradient
  // does at large k, has the last word, and the step stops there).
  if (-slope <= 64.0 * std::numeric_limits<double>::epsilon() * std::abs(before)) return false;
  for (alpha = 1.0;; alpha *= 0.5) {
    trial = x;
    for (int u = 0; u < map_.unknowns(); ++u) {
      trial.col(map_.particle_of[static_cast<std::size_t>(u)]) += alpha * dx.segment<3>(3 * u);
    }
    const double after = objective(trial, y);
    if (std::isfinite(after) && after <= before + kArmijo * alpha * slope) return true;
    if (backtracks == 2 * max_backtracks) return false;
    ++backtracks;
  }
}

StepReport Solver::iterate(Eigen::Matrix3Xd& x, Eigen::VectorXd& lambda, const Eigen::Matrix3Xd& y,
                           const Settings& settings, const IterationCallback& on_iteration) const {
  check(settings);
  const Eigen::Index n = inv_mass_.size();
  if (x.cols() != n || y.cols() != n) throw std::invalid_argument("Solver::iterate: x and y need one column per particle");
  if (lambda.size() != static_cast<Eigen::Index>(springs_.size())) {
    throw std::invalid_argument("Solver::iterate: lambda needs one entry per spring");
  }
  StepReport report;
  report.linear_solver = all_compliant() ? "schur" : "kkt";
  const lab07::Method method = all_compliant() ? lab07::Method::kSchur : lab07::Method::kKkt;
  const bool schur = method == lab07::Method::kSchur && !springs_.empty();  // schur_solve; else solve_stiff
  lab07::StepSettings linear;
  linear.dt = dt_;
  linear.gravity = settings.gravity;
  linear.method = method;
  const Timer clock;
  double excluded = 0.0;  // time spent only for the records
  // Compressed springs kept (kKeep): the exact matrix where the Cholesky
  // factors it. Where it refuses, the iteration drops a part δ of the
  // compressed springs' K_g (README.md, "Compression"): δ starts each step at
  // 0; a refusal raises it to kFirstDropped, then 4δ, up to 1 (all dropped,
  // always definite). An iteration that factored with δ > 0 lets the next one
  // try δ/4 (0 below kFirstDropped), so that the exact matrix, and its
  // quadratic convergence, comes back once the step's own matrix is definite;
  // a lowered δ that is refused again waits 1, 2, 4, … iterations before the
  // next lowering, so a buckled cloth pays a refused factorization on a few
  // iterations of a step, not on every one.
  double dropped = 0.0;
  int lower_at = 1, lower_wait = 1;  // the next iteration that may lower δ; the wait after a refused lowering

  auto evaluate = [&](const Eigen::Matrix3Xd& at, const Eigen::VectorXd& multipliers) {
    return residuals(at, y, multipliers, springs_, inv_mass_, map_, compliance_, dt_);
  };
  Residuals r = evaluate(x, lambda);
  Convergence c = convergence(r, length_scale_, settings.tolerance);
  double psi = merit(r, inv_mass_, map_, weights_, dt_);
  auto record = [&](int iteration, double alpha, int backtracks) {
    if (!on_iteration) return false;
    const Timer timer;
    const bool stop = on_iteration(
        {iteration, c.force_error, c.constraint_error, psi, alpha, backtracks, clock.seconds() - excluded, &x});
    excluded += timer.seconds();
    return stop;
  };
  // A residual or merit that is not finite at the start would reach your
  // sufficient_decrease as ψ(0): the step stops here and says which term.
  if (!all_finite(y)) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the prediction y = x + dt v + dt^2 g is not finite at dt = %.3g s: use a smaller dt (--dt)", dt_);
    report.problem = text;
    return report;
  }
  if (!r.force.allFinite() || !r.constraint.allFinite() || !std::isfinite(psi)) {
    report.problem = !r.force.allFinite()
                         ? "residuals() returned a force residual r_x = M(x - y)/dt^2 - J^T lambda that is not finite "
                           "at the step's start (check the inverse masses it divides by, and the scene's masses)"
                     : !r.constraint.allFinite()
                         ? "residuals() returned a constraint residual r_lambda = phi + C lambda that is not finite at "
                           "the step's start"
                         : "the merit psi is not finite at the step's start (the residuals are): a mass or a "
                           "stiffness too large for the merit's squares in a double; scale the scene's units";
    return report;
  }
  bool stopped = record(0, 0.0, 0);
  Particles at;  // lab 07's linearisation reads positions and inverse masses from a state
  at.inv_mass = inv_mass_;
  at.v.setZero(3, n);
  for (int k = 1; k <= settings.iterations && !stopped; ++k) {
    if ((settings.tolerance > 0.0 && c.converged) || psi == 0.0) break;
    const std::string where = "constrained newton iteration " + std::to_string(k) + ": ";
    const Eigen::VectorXd velocity = rebased_velocity(x, y, map_, settings.gravity, dt_);
    // Lab 07's linearisation at x with the re-based velocity: the KKT solves'
    // input (made only when one runs).
    auto linearized = [&]() {
      at.x = x;
      lab07::LinearizedStep step = lab07::linearize(at, springs_, map_, linear);
      step.velocity = velocity;
      return step;
    };
    lab07::StepSolution solution;
    Eigen::VectorXd rhs;  // the Schur right-hand side: −Δt ∇g(x)
    const lab09::Compression compression = settings.compression;
    if (schur && compression == lab09::Compression::kKeep) {
      bool lowered = false;
      if (dropped > 0.0 && k >= lower_at) {
        dropped = dropped < 4.0 * kFirstDropped ? 0.0 : 0.25 * dropped;
        lowered = true;
      }
      for (;;) {
        solution = schur_solve(x, velocity, lambda, settings.gravity, compression, dropped, rhs);
        if (solution.ok || dropped == 1.0) break;
        ++report.refused_factorizations;
        if (lowered) {
          lower_at = k + lower_wait;
          lower_wait *= 2;
          lowered = false;
        }
        dropped = dropped == 0.0 ? kFirstDropped : std::min(1.0, 4.0 * dropped);
      }
      if (lowered) lower_wait = 1;
    } else if (schur) {
      solution = schur_solve(x, velocity, lambda, settings.gravity, compression, 0.0, rhs);
    } else {
      solution = lab09::solve_stiff(linearized(), lab09::geometric_stiffness(x, springs_, lambda, map_, settings.compression),
                                    method);
    }
    const auto unknowns = static_cast<Eigen::Index>(velocity.size());
    const auto constraints = static_cast<Eigen::Index>(springs_.size());
    const std::string problem = lab07::solution_problem(solution, unknowns, constraints);
    if (!problem.empty()) {
      report.problem = where + (schur ? problem : hard_set_problem(x, problem));
      return report;
    }
    // The safeguard: halve α until the merit falls enough (sufficient_decrease).
    double alpha = 1.0;
    int backtracks = 0;
    Eigen::Matrix3Xd trial;
    Eigen::VectorXd trial_lambda;
    Residuals trial_r;
    double trial_psi = 0.0;
    auto line_search = [&](const lab07::StepSolution& direction) {
      const Eigen::VectorXd dx = dt_ * direction.velocity;
      const Eigen::VectorXd dlambda = direction.lambda - lambda;
      for (alpha = 1.0;; alpha *= 0.5) {
        trial = x;
        for (int u = 0; u < map_.unknowns(); ++u) {
          trial.col(map_.particle_of[static_cast<std::size_t>(u)]) += alpha * dx.segment<3>(3 * u);
        }
        trial_lambda = lambda + alpha * dlambda;
        trial_r = evaluate(trial, trial_lambda);
        trial_psi = merit(trial_r, inv_mass_, map_, weights_, dt_);
        if (sufficient_decrease(psi, trial_psi, alpha)) return true;
        if (backtracks == settings.max_backtracks) return false;
        ++backtracks;
      }
    };
    bool accepted = line_search(solution);
    const bool exact = compression == lab09::Compression::kKeep && dropped == 0.0;
    if (!accepted && !exact && schur && settings.exact_rescue) {
      // Only the exact Newton direction is sure to lower ψ (ψ'(0) = −2ψ): the
      // dropped one found no step length, so this iteration takes lab 07's
      // KKT solve (an LU) of the exact, indefinite system instead.
      ++report.exact_rescues;
      const lab07::StepSolution rescue =
          lab09::solve_stiff(linearized(), lab09::geometric_stiffness(x, springs_, lambda, map_, lab09::Compression::kKeep),
                             lab07::Method::kKkt);
      if (lab07::solution_problem(rescue, unknowns, constraints).empty()) {
        report.backtracks += backtracks;
        backtracks = 0;
        accepted = line_search(rescue);
      }
    }
    report.backtracks += backtracks;
    if (!accepted && schur) {
      // The fallback past a fold (README.md, "Past a fold"): ψ found no step
      // length, but the matrix just factored (with all or part of the
      // compression dropped) is positive definite, so Δx descends on g, lab 06's
      // objective, whose minimiser is the step. A
      // backtracking search on g along it, then λ re-warmed to the springs'
      // forces there (warm_start), and the next iteration is the constrained
      // one again, from a point where its matrix is g's exact Hessian.
      backtracks = 0;
      accepted = descend_on_g(x, y, dt_ * solution.velocity, -rhs.dot(solution.velocity), settings.max_backtracks,
                              trial, alpha, backtracks);
      report.backtracks += backtracks;
      if (accepted) {
        ++report.fallbacks;
        trial_lambda = warm_start(trial, springs_, lambda, Warm::kForces);
        trial_r = evaluate(trial, trial_lambda);
        trial_psi = merit(trial_r, inv_mass_, map_, weights_, dt_);
        if (!std::isfinite(trial_psi)) accepted = false;
      }
    }
    if (!accepted) {
      report.failed_decreases = 1;  // x and λ stay at the last accepted iterate
      // With hard springs there is no g to fall back on. A step that cannot
      // leave its start, with errors far above round-off (above √tolerance),
      // would end where it began, with v = 0: the cloth would hang frozen
      // while every step said only "not converged". It is the step's failure.
      const double floor = std::sqrt(settings.tolerance);
      if (!schur && k == 1 && std::max(c.force_error, c.constraint_error) > floor) {
        char text[640];
        std::snprintf(text, sizeof text,
                      "%sno step length along Newton's direction lowers the merit from the step's start (force error "
                      "%.2g, constraint error %.2g): the hard constraints' KKT system is too ill-conditioned here for "
                      "its direction (a sheet hung from one point folds until its rows are nearly dependent). Give the "
                      "springs a finite stiffness (--stiffness): the compliant step falls back on lab 06's g",
                      where.c_str(), c.force_error, c.constraint_error);
        report.problem = text;
        return report;
      }
      break;
    }
    x = std::move(trial);
    lambda = std::move(trial_lambda);
    r = std::move(trial_r);
    psi = trial_psi;
    c = convergence(r, length_scale_, settings.tolerance);
    report.iterations_done = k;
    stopped = record(k, alpha, backtracks);
  }
  report.converged = (settings.tolerance > 0.0 && c.converged) || psi == 0.0;
  report.force_error = c.force_error;
  report.constraint_error = c.constraint_error;
  report.merit = psi;
  if (!all_finite(x) || !lambda.allFinite()) report.problem = "constrained newton: non-finite iterate";
  return report;
}

// ------------------------------------------------------------------ a run

double total_energy(const Particles& particles, const std::vector<Spring>& springs, const Eigen::Vector3d& gravity) {
  return kinetic_energy(particles) + potential_energy(particles, gravity) + lab09::spring_energy(particles.x, springs);
}

RunResult run_steps(Particles& particles, Solver& solver, const Settings& settings, int steps,
                    const RunIterationCallback& on_iteration, const FrameOutput& output,
                    const RunStepCallback& on_step) {
  if (steps < 0) throw std::invalid_argument("run_steps: steps must be >= 0");
  const std::vector<Spring>& springs = solver.springs();
  RunResult result;
  StepReport report;
  auto step = [&](int s) {
    IterationCallback each = nullptr;
    if (on_iteration) {
      each = [&](const IterationRecord& iteration) {
        on_iteration(s, iteration);
        return false;
      };
    }
    report = solver.step(particles, settings, each);
    result.iterations_done += report.iterations_done;
    result.backtracks += report.backtracks;
    result.failed_decreases += report.failed_decreases;
    result.fallbacks += report.fallbacks;
    result.exact_rescues += report.exact_rescues;
    result.refused_factorizations += report.refused_factorizations;
    if (report.problem.empty() && !report.converged && settings.tolerance > 0.0) ++result.unconverged_steps;
    if (report.problem.empty() && on_step) on_step(s, report);
    return StepVerdict{report.problem, report.problem.empty(), report.seconds};
  };
  auto measured = [&](int s, double) {
    const StepReport done = s > 0 ? report : StepReport{};
    const StrainStats strain = strain_stats(particles.x, springs);
    const double energy = total_energy(particles, springs, settings.gravity);
    return FrameMeasure{strain, energy, {},
                        {static_cast<long long>(done.iterations_done), static_cast<long long>(done.converged ? 1 : 0),
                         static_cast<long long>(done.backtracks), static_cast<long long>(done.failed_decreases),
                         static_cast<long long>(done.fallbacks), static_cast<long long>(done.exact_rescues),
                         static_cast<long long>(done.refused_factorizations),
                         done.force_error, done.constraint_error, done.merit, done.seconds, strain.max, strain.rms,
                         energy},
                        {}};
  };
  const double scale = energy_scale(particles, settings.gravity, solver.dt()) +
                       lab09::spring_energy(particles.x, springs);
  FrameOutput with_index = output;
  with_index.index_column = "step";
  const FrameLoopResult run =
      run_frame_loop(particles, step, measured, frame_plan(steps, solver.dt(), scale), with_index);
  copy_outcome(run, result, result.steps_done, result.problem_step);
  result.step_failed = run.step_failed;
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  return result;
}

std::vector<std::string> step_columns() {
  return {"iterations",       "converged", "backtracks", "failed_decreases", "fallbacks",  "exact_rescues",
          "refused_factorizations", "force_error",      "constraint_error", "merit", "seconds",  "max_strain", "rms_strain", "total_energy"};
}

}  // namespace cl::lab13
