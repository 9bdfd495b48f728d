#pragma once
// Lab 13 — given code: the constrained Newton iteration built from your six
// functions (constrained_newton.h) and lab 09's solves (each iteration is a
// lab 09 step re-based at the iterate), its safeguard (backtracking on the
// merit), and the loop over a scene's steps on common/frame_loop.h.
// It owns the state (the previous step's λ); the functions stay stateless.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/frame_loop.h"
#include "common/particles.h"
#include "common/sparse.h"
#include "common/spring_blocks.h"
#include "constrained_newton.h"
#include "constrained.h"
#include "geometric_stiffness.h"
#include "step.h"

namespace cl::lab13 {

// The first iterate x⁰: the start of the step (x_old, where the springs
// already carry their forces) or the prediction y.
enum class Start { kPositions, kPrediction };
const char* start_name(Start start);  // "x" or "prediction"
Start start_from_name(const std::string& name);  // throws std::invalid_argument
const char* warm_name(Warm warm);  // "forces" or "zero"
Warm warm_from_name(const std::string& name);  // throws std::invalid_argument

struct Settings {
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;       // the most Newton iterations per step, >= 0
  double tolerance = 1e-8;   // convergence(): both errors ≤ this ends the step (0: run every iteration)
  Start start = Start::kPositions;
  Warm warm = Warm::kForces;
  // Compressed springs in K_g (README.md, "Compression"): kept (kKeep, the
  // exact Jacobian: quadratic convergence near the step), a part of it
  // dropped where the Cholesky refuses the matrix (0.01, 0.04, … up to all;
  // StepReport::refused_factorizations) and taken back as the iterations go;
  // or always dropped (kDrop: always definite, but a slow linear tail).
  lab09::Compression compression = lab09::Compression::kKeep;
  int max_backtracks = 12;   // halvings of α before the step gives up (α ≥ 2⁻¹²)
  // A direction that is not the exact Newton one (compression partly or
  // wholly dropped) and lowers ψ for no α: true, the iteration first tries lab
  // 07's KKT solve (an LU) of the exact system (StepReport::exact_rescues);
  // false (the default), it goes straight to the fallback on g (README.md,
  // "Past a fold"). On a 128² curtain the LU costs 15 s an iteration.
  bool exact_rescue = false;
};


struct IterationRecord {
  int iteration = 0;          // 0: the first iterate (x⁰, λ⁰)
  double force_error = 0.0;   // Convergence::force_error
  double constraint_error = 0.0;
  double merit = 0.0;         // ψ, J
  double alpha = 0.0;         // the step length taken (0 at iteration 0)
  int backtracks = 0;         // halvings of α in this iteration
  double seconds = 0.0;       // wall time of the method's own work since the step began
  const Eigen::Matrix3Xd* x = nullptr;  // the iterate (valid during the callback only)
};
// Returns true to end the step at this iterate.
using IterationCallback = std::function<bool(const IterationRecord&)>;

struct StepReport {
  int iterations_done = 0;
  bool converged = false;
  int backtracks = 0;          // halvings of α over the step
  int failed_decreases = 0;    // 1 when no α ≥ 2^-max_backtracks decreased ψ: the step stopped there
  int fallbacks = 0;           // iterations whose direction lowered ψ for no α and took a descent step on g
  int exact_rescues = 0;       // iterations that took lab 07's KKT solve instead (Settings::exact_rescue)
  int refused_factorizations = 0;  // matrices the Cholesky refused (that iteration then drops more of the compression)
  double force_error = 0.0, constraint_error = 0.0, merit = 0.0;  // at the result
  double seconds = 0.0;
  std::string linear_solver;   // "schur" (every c_e > 0: lab 09's primal solve) or "kkt" (some c_e = 0)
  // Non-empty: a solve failed, or (hard springs) no step length lowers ψ at
  // the first iteration while an error is above √tolerance (README.md, "Where
  // it holds"); the particles are unchanged.
  std::string problem;
};

// The springs' mean rest length (m): convergence()'s length scale. 1 m when
// there are no springs or every rest length is 0.
double length_scale(const std::vector<Spring>& springs);

// One scene's solver: the springs, the movable map, the compliance and the
// merit's weights, made once; the previous step's λ. A spring whose two ends
// are pinned is left out (nothing can move it; as a hard constraint it would
// make the KKT matrix singular): springs() and every λ are over the others.
class Solver {
 public:
  // Throws std::invalid_argument for a dt that is NaN, infinite or ≤ 0, a
  // spring index out of range, or springs that lab 07's compliance_of refuses.
  Solver(const Eigen::VectorXd& inv_mass, const std::vector<Spring>& springs, double dt);

  // One step: y = lab06::predict, x⁰ (settings.start), λ⁰ = warm_start(x_old,
  // springs, the previous step's λ, settings.warm), iterate(), then
  // v ← (x − x_old)/Δt (0 for pinned particles), x ← x, and λ kept for the
  // next step. When iterate() reports a problem the particles are unchanged.
  StepReport step(Particles& particles, const Settings& settings, const IterationCallback& on_iteration = nullptr);

  // The iteration alone: x (3 × n, pinned columns as they are) and lambda
  // (one per spring) towards the step for the prediction y. Each iteration:
  // residuals, convergence (stop when converged), v̂ = rebased_velocity, then
  // lab 09's system at x for v̂ with K_g from λ (compression as
  // Settings::compression says): when every c_e > 0 its primal Schur solve,
  // the eliminated matrix M − Δt² K_g + Δt² Jᵀ C⁻¹ J written spring by spring
  // into a fixed pattern (common/spring_blocks.h) and refactored with the
  // kept symbolic analysis (the matrix and right-hand side of
  // lab09::eliminated_system, to round-off); else lab 07's linearisation at x
  // and lab 09's solve_stiff (the KKT solve). Δx = Δt v̂_new, then the
  // safeguard: α = 1, ½, ¼, … until sufficient_decrease(ψ(0), ψ(α), α) with
  // x + αΔx and λ + α(λ_new − λ).
  StepReport iterate(Eigen::Matrix3Xd& x, Eigen::VectorXd& lambda, const Eigen::Matrix3Xd& y,
                     const Settings& settings, const IterationCallback& on_iteration = nullptr) const;

  const Eigen::VectorXd& previous_lambda() const { return previous_lambda_; }
  const std::vector<Spring>& springs() const { return springs_; }
  const MovableMap& map() const { return map_; }
  const Eigen::VectorXd& compliance() const { return compliance_; }
  double dt() const { return dt_; }
  bool all_compliant() const;  // every c_e > 0 (lab 09's primal solve); true without springs

 private:
  Eigen::VectorXd inv_mass_;
  std::vector<Spring> springs_;
  MovableMap map_;
  Eigen::VectorXd compliance_;  // lab 07's: empty when every spring is hard
  Eigen::VectorXd weights_;     // merit_weights
  double dt_;
  double length_scale_;
  Eigen::VectorXd previous_lambda_;
  // The primal Schur matrix's fixed pattern and its factorization, kept for
  // the symbolic analysis (both empty unless every c_e > 0 and m > 0).
  mutable SpringBlockMatrix eliminated_;
  mutable SpdFactorization factor_;

  // Lab 09's primal Schur solve (every c_e > 0) of the system at x for the
  // re-based velocity, with K_g from lambda (compression as given): the
  // eliminated matrix and right-hand side of lab09::eliminated_system,
  // assembled per spring into eliminated_, then v_new and
  // λ = −C⁻¹(φ + Δt J v_new) as solve_stiff_schur gives them.
  // rhs: the right-hand side, −Δt ∇g(x).
  // dropped: δ in [0, 1], the part of a compressed spring's K_g left out
  // under kKeep (kDrop leaves all of it out).
  lab07::StepSolution schur_solve(const Eigen::Matrix3Xd& x, const Eigen::VectorXd& velocity,
                                  const Eigen::VectorXd& lambda, const Eigen::Vector3d& gravity,
                                  lab09::Compression compression, double dropped, Eigen::VectorXd& rhs) const;
  // A KKT solve's problem that says "singular", in the scene's words: which
  // hard springs (a duplicate, coincident ends) or the count, and what to do.
  std::string hard_set_problem(const Eigen::Matrix3Xd& x, const std::string& problem) const;
  // g(x) = ½ (x − y)ᵀM(x − y)/Δt² + Σ ½ k_e φ_e², lab 06's objective (every c_e > 0), J.
  double objective(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) const;
  // The fallback's search: x + αΔx for α = 1, ½, … (at most 2·max_backtracks
  // halvings) until Armijo's rule on g with `slope` = ∇g·Δx < 0; false when
  // none is accepted (or the slope is not negative).
  bool descend_on_g(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Eigen::VectorXd& dx, double slope,
                    int max_backtracks, Eigen::Matrix3Xd& trial, double& alpha, int& backtracks) const;
};

// ------------------------------------------------------------------ a run

struct RunResult {
  int steps_done = 0;
  long long iterations_done = 0;
  int backtracks = 0;
  int failed_decreases = 0;
  int fallbacks = 0;
  int exact_rescues = 0;
  int refused_factorizations = 0;
  int unconverged_steps = 0;  // steps that ended at the iteration cap or a failed decrease
  double seconds = 0.0;
  double energy_start = 0.0, energy_end = 0.0;
  std::string problem;
  int problem_step = -1;
  bool step_failed = false;  // the problem is a step that could not be taken (a singular system)
};
using RunIterationCallback = std::function<void(int step, const IterationRecord&)>;
using RunStepCallback = std::function<void(int step, const StepReport&)>;  // after every step taken

// total energy: kinetic + gravity + ½ k φ² over the finite springs (J).
double total_energy(const Particles& particles, const std::vector<Spring>& springs, const Eigen::Vector3d& gravity);

// Runs `steps` steps in common/frame_loop.h's loop (health, the energy
// verdict with the scene's energy scale plus its initial elastic energy, the
// per-step CSV of step_columns() when output asks for it).
RunResult run_steps(Particles& particles, Solver& solver, const Settings& settings, int steps,
                    const RunIterationCallback& on_iteration = nullptr, const FrameOutput& output = {},
                    const RunStepCallback& on_step = nullptr);

// iterations, converged, backtracks, failed_decreases, fallbacks, exact_rescues, refused_factorizations, force_error,
// constraint_error, merit, seconds, max_strain, rms_strain, total_energy.
std::vector<std::string> step_columns();

}  // namespace cl::lab13
