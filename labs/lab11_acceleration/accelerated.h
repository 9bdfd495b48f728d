#pragma once
// Lab 11 — given code: the accelerated loops around the functions of
// acceleration.h, built on the earlier labs' code through their headers:
// lab 06's local step, global step, system matrix, objective and Newton step;
// lab 03's Jacobi sweep and lab 02's Gauss-Seidel sweep inside lab 04's PBD
// step; and the loop over a scene's steps on common/frame_loop.h. It owns the
// state; the functions of acceleration.h stay stateless.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../lab06_projective_dynamics/simulation.h"
#include "acceleration.h"
#include "common/constraints.h"
#include "common/frame_loop.h"
#include "common/particles.h"
#include "common/sparse.h"
#include "pbd.h"

namespace cl::lab11 {

// The projective dynamics family minimises lab 06's objective g; the PBD family
// projects the springs as hard constraints (their stiffness is not used).
enum class Method { kPd, kPdChebyshev, kPdLbfgs, kNewton, kJacobi, kJacobiChebyshev, kGaussSeidel };
const char* method_name(Method method);  // "pd", "pd-chebyshev", "pd-lbfgs", "newton", "jacobi", …
// Throws std::invalid_argument for a name that is none of them.
Method method_from_name(const std::string& name);
bool minimises_objective(Method method);  // pd, pd-chebyshev, pd-lbfgs, newton

struct Settings {
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;     // K: iterations (PD family) or sweeps (PBD family), >= 0
  double tolerance = 0.0;  // PD family: stop once (g_prev − g)/g_prev < tolerance (lab 06's rule; 0: all K)
  double rho = 0.0;        // Chebyshev: the spectral radius, [0, 1)
  double gamma = 1.0;      // Chebyshev: the under-relaxation, (0, 2)
  int delay = 1;           // Chebyshev: S >= 1, the first S iterations are plain (ω = 1)
  int history = 5;         // L-BFGS: m >= 0 pairs
};

// Reported once before the first iteration (iteration 0) and after each one.
struct IterationRecord {
  int iteration = 0;
  double objective = 0.0;   // PD family: g(x^k), J. PBD family: Σ_e strain_e², the restart's merit
  double max_strain = 0.0;  // max_e strain error (common/metrics.h)
  double omega = 1.0;       // the weight used (1 for plain iterations)
  bool restarted = false;   // the accelerated iterate was rejected here
  double seconds = 0.0;     // wall time of the method's own work since the step began
};
// Returns true to end the step at this iterate.
using IterationCallback = std::function<bool(const IterationRecord&)>;

struct StepReport {
  int iterations_done = 0;
  double objective = 0.0;        // as in IterationRecord, at the result
  int restarts = 0;              // Chebyshev
  int failed_line_searches = 0;  // L-BFGS and Newton: no decrease found (the step stops there)
  // L-BFGS: iterations whose two-loop direction was not a descent (∇gᵀd >= 0
  // or not finite), replaced by PD's −A⁻¹∇g with the history forgotten. A
  // correct lbfgs_direction never needs one on a well-posed scene (its H stays
  // positive definite); a wrong one needs them all the time and then runs as
  // plain PD, which converges anyway: this count is where it shows.
  int descent_fallbacks = 0;
  bool converged = false;        // stopped by the tolerance, or at round-off
  double seconds = 0.0;
  std::string problem;           // non-empty: the step failed; the particles are unchanged
};

// The relative slack of the restart rule: rises within round-off are not restarts.
constexpr double kRestartSlack = 1e-13;

// ------------------------------------------------------------------ the accelerated loop

// The loop every Chebyshev-accelerated method of labs 11 and 12 runs (Wang
// 2015: PD here, Jacobi PBD here, VBD in lab 12), around the plain iteration
// it accelerates. Iteration k: q̂ = F(x); with `accelerated` the weight ω
// (ω = 1 for the first `delay` iterations, then chebyshev_weight with j
// counted from iteration `delay` or from the last restart) mixes q̂, x and the
// iterate before it by chebyshev_update (pinned columns put back from
// `held`); restart_needed on the merit (slack kRestartSlack) rejects the mix
// for q̂ and restarts the weights. Without `accelerated` the iterate is q̂.
struct AcceleratedLoop {
  int iterations = 0;        // K >= 0
  double tolerance = 0.0;    // stop once the merit's relative decrease falls below it (lab 06's rule; 0: all K)
  bool accelerated = false;  // Chebyshev's weights (false: the plain iteration)
  double rho = 0.0;          // the weights' spectral radius, [0, 1)
  double gamma = 1.0;        // the under-relaxation, (0, 2)
  int delay = 1;             // S >= 1
  std::string name;          // the method, for the problem's text
  std::string unit = "iteration";  // what one iteration is called there ("sweep")
};

// x ↦ F(x): the plain iterate into `plain` (resized; it does not alias x).
using PlainIteration = std::function<void(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain)>;
// The merit that the restart rule and the tolerance judge (PD and VBD: g, J; PBD: strain_merit).
using Merit = std::function<double(const Eigen::Matrix3Xd& x)>;
// Called with each iterate's record (iteration 0: the start; max_strain left
// 0) and the iterate, which it may measure: its time is not counted in the
// records' seconds. Returns true to end the loop at this iterate.
using IterateCallback = std::function<bool(const IterationRecord& record, const Eigen::Matrix3Xd& x)>;

// Runs the loop from x (3 × n, its pinned columns those of `held`; inv_mass: n
// entries) and leaves the last iterate in x. The merit is evaluated every
// iteration that the weights, the tolerance or a record need (for the plain
// iteration's records outside the measured time). A non-finite iterate ends
// the loop with the problem "<name>: non-finite positions after <unit> k".
// The report's objective is the merit at x (not set after a problem); its
// seconds are left to the caller.
StepReport accelerated_iterations(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& held, const Eigen::VectorXd& inv_mass,
                                  const PlainIteration& plain_iteration, const Merit& merit,
                                  const AcceleratedLoop& loop, const IterateCallback& on_iterate = nullptr);

// ρ of a plain iteration, measured from x: the update lengths ‖F(q) − q‖ of up
// to `iterations` iterations, ending before one that is not finite or at most
// 1e-12 · scale (round-off: noise, not the rate), given to
// estimate_spectral_radius; 0 when fewer than 2 were measured. Throws
// std::invalid_argument for iterations < 2.
double estimate_plain_rho(Eigen::Matrix3Xd x, const PlainIteration& plain_iteration, int iterations, double scale);

// ------------------------------------------------------------------ the solver

// One scene's solver. The PD pieces (lab 06's Problem, A factored once) are
// made on the first step of a PD-family method; the constraint set (lab 04) on
// the first PBD step.
class Solver {
 public:
  // Throws std::invalid_argument for sizes that disagree.
  Solver(Eigen::VectorXd inv_mass, std::vector<Spring> springs, double dt);

  // One step of size dt: prediction, K iterations of `method`, velocity update.
  // Throws std::invalid_argument for settings out of range (and what lab 06's
  // make_problem throws, for a PD-family method).
  StepReport step(Particles& particles, Method method, const Settings& settings,
                  const IterationCallback& on_iteration = nullptr);

  // The PD family without the step around it: iterates x (3 × n, pinned
  // columns = y) towards the minimiser of g for the prediction y.
  StepReport minimise(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, Method method, const Settings& settings,
                      const IterationCallback& on_iteration = nullptr);

  // ρ of the plain iteration of `method`'s family (pd or jacobi), measured on
  // one step from `start` (which is not changed): the update lengths of up to
  // `iterations` plain iterations (ending early where they reach round-off),
  // given to estimate_spectral_radius.
  double estimate_rho(const Particles& start, Method method, const Settings& settings, int iterations = 400);

  const lab06::Problem& problem();  // makes the PD pieces if needed
  double dt() const { return dt_; }
  const std::vector<Spring>& springs() const { return springs_; }
  double factor_seconds() const { return factor_seconds_; }
  int factorizations() const;

 private:
  void require_pd();
  PlainIteration pd_iteration(const Eigen::Matrix3Xd& y);  // one local/global iteration of lab 06 for y
  Eigen::Matrix3Xd pbd_prediction(const Particles& particles, const Eigen::Vector3d& gravity) const;
  PlainIteration pbd_iteration(Method method);  // one sweep: Gauss-Seidel (lab 02) or Jacobi (lab 03)
  StepReport lbfgs_pd(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Settings& settings,
                      const IterationCallback& on_iteration);
  StepReport pbd(Particles& particles, Method method, const Settings& settings,
                 const IterationCallback& on_iteration);

  Eigen::VectorXd inv_mass_;
  std::vector<Spring> springs_;
  double dt_;
  std::optional<lab06::Problem> problem_;
  SpdFactorization factor_{SpdBackend::kSimplicial};  // A, kept for the whole scene (one-pass solve3), as lab 06
  std::unique_ptr<lab06::Solver> newton_;
  std::optional<lab04::ConstraintSet> constraints_;
  double factor_seconds_ = 0.0;
  std::string setup_problem_;
};

// v ↦ A⁻¹ v for a vector stacked over the unknowns (3 per unknown), with the
// factor of lab 06's A: the initial inverse Hessian of L-BFGS.
Eigen::VectorXd apply_inverse(const SpdFactorization& factor, const Eigen::VectorXd& stacked);

// Σ_e strain_error_e², the PBD family's restart merit (dimensionless).
double strain_merit(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// ------------------------------------------------------------------ a run

struct StepRecord {
  int step = 0;           // 0: the initial state
  StepReport report;      // step 0: empty
  StrainStats strain;
  double total_energy = 0.0;  // kinetic + gravity (+ springs for the PD family), J
  std::string problem;    // empty when healthy
};
using StepCallback = std::function<void(const StepRecord&, const Particles&)>;
// Every iteration of step `step` (1, 2, …), for a per-iteration record.
using RunIterationCallback = std::function<void(int step, const IterationRecord&)>;

struct RunResult {
  int steps_done = 0;
  long long iterations_done = 0;
  int restarts = 0;
  int failed_line_searches = 0;
  int descent_fallbacks = 0;
  double seconds = 0.0;
  double energy_start = 0.0, energy_end = 0.0;
  std::string problem;    // empty unless the run stopped unhealthy
  int problem_step = -1;
};

// Runs `steps` steps in common/frame_loop.h's loop: it stops at the first
// failed or unhealthy step (common/health.h), or one whose total energy rose
// more than the scene's energy scale (plus, for the PD family, its initial
// elastic energy) above its start, and writes the per-step CSV of
// step_columns() and the trajectory when `output` asks for them.
RunResult run_steps(Particles& particles, Solver& solver, Method method, const Settings& settings, int steps,
                    const StepCallback& on_step = nullptr, const RunIterationCallback& on_iteration = nullptr,
                    const FrameOutput& output = {});

// objective, iterations, converged, restarts, failed_line_searches,
// descent_fallbacks, seconds, max_strain, rms_strain, total_energy.
std::vector<std::string> step_columns();

}  // namespace cl::lab11
