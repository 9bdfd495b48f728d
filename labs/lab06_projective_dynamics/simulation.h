#pragma once
// Lab 06 — given code: the implicit-Euler step by projective dynamics (your
// five functions, K times) or by Newton's method on the same objective, and
// the loop over a scene's steps with its health checks. It owns the state;
// the functions of projective_dynamics.h stay stateless.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/particles.h"
#include "common/sparse.h"
#include "common/spring_blocks.h"
#include "projective_dynamics.h"

namespace cl::lab06 {

enum class Method { kProjectiveDynamics, kNewton };
const char* method_name(Method method);  // "pd" or "newton"

struct StepSettings {
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;     // K: PD iterations, or the most Newton iterations; >= 0
  double tolerance = 0.0;  // stop once the objective's relative decrease (g_prev − g)/g_prev
                           // falls below this (0: run all K)
};

// The prediction y = x + Δt v + Δt² g for movable particles; y = x for pinned ones.
Eigen::Matrix3Xd predict(const Particles& particles, const Eigen::Vector3d& gravity, double dt);

// Σ_e k_e/2 (‖x_i − x_j‖ − L_e)², the springs' energy (J).
double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// Reported after each iteration, and once before the first (iteration 0, x = y).
struct IterationRecord {
  int iteration = 0;
  double objective = 0.0;  // g(x^k), J
  double seconds = 0.0;    // wall time of the method's own work since the step began
                           // (not the objective evaluations made only for this record)
  int factorizations = 0;  // the solver's count so far
  const Eigen::Matrix3Xd* x = nullptr;  // the iterate (valid during the callback only; lab 13
                                        // measures its distance to the step)
};
// Returns true to end the step at this iterate (the experiment stops a run
// once it is close enough to the minimum).
using IterationCallback = std::function<bool(const IterationRecord&)>;

struct StepReport {
  int iterations_done = 0;
  double objective = 0.0;    // g at the result, J
  double seconds = 0.0;      // wall time of the step
  bool converged = false;    // stopped by the tolerance, or Newton at round-off
  int failed_decreases = 0;  // Newton: a line search found no decrease (the step stops there)
  std::string problem;       // non-empty: the step could not be done; the particles are unchanged
};

// Newton's Hessian (newton_hessian, below) assembled into a fixed sparsity
// pattern, values only (common/spring_blocks.h): the pattern, and where each
// spring's four 3×3 blocks and each unknown's mass go in it, are found once
// (the constructor); update() rewrites the values in place, with no triplets
// and no sort. A spring's blocks are stored even where their values are 0, so
// the pattern is the same for every x, and the factorization's ordering and
// symbolic analysis hold for every iteration.
class HessianAssembly {
 public:
  HessianAssembly() = default;  // empty(): no pattern yet
  explicit HessianAssembly(const Problem& problem);
  bool empty() const { return blocks_.empty(); }
  // newton_hessian(problem, x, clamp), written into the pattern. `problem`
  // must be the constructor's (same unknowns and springs: std::invalid_argument
  // otherwise). The reference stays valid until the next update.
  const SparseMatrix& update(const Problem& problem, const Eigen::Matrix3Xd& x, bool clamp = true);

 private:
  SpringBlockMatrix blocks_;  // full (both triangles), compressed
};

// One scene's solver. Projective dynamics factors A = system_matrix(problem)
// once, here; Newton factors its Hessian afresh in every iteration (a new
// numeric factorization; the fill-reducing ordering depends only on the
// sparsity pattern, which never changes, so it is computed once).
class Solver {
 public:
  // Throws what system_matrix throws (PD). When A cannot be factored (not
  // positive definite to working precision) every step reports setup_problem().
  Solver(Problem problem, Method method);

  // One implicit-Euler step of size problem().dt: y = predict(...), x⁰ = y,
  // K iterations, then v ← (x^K − x)/Δt (0 for pinned particles), x ← x^K.
  StepReport step(Particles& particles, const StepSettings& settings,
                  const IterationCallback& on_iteration = nullptr);

  Method method() const { return method_; }
  const Problem& problem() const { return problem_; }
  int factorizations() const { return factorizations_; }
  double factor_seconds() const { return factor_seconds_; }  // total wall time spent factoring
  // The factorization the method uses: common/sparse.h's backend_name of its
  // factor (PD: A's; Newton: the Hessian's, "simplicial-ldlt" before the first).
  const char* linear_solver() const;
  const std::string& setup_problem() const { return setup_problem_; }

 private:
  StepReport projective_dynamics(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const StepSettings& settings,
                                 const IterationCallback& on_iteration) const;
  StepReport newton(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const StepSettings& settings,
                    const IterationCallback& on_iteration);

  Problem problem_;
  Method method_;
  SpdFactorization factor_{SpdBackend::kSimplicial};  // PD: A, kept for the whole scene (one-pass solve3)
  SpdFactorization hessian_factor_;  // Newton: refactored every iteration (the pattern's
                                     // ordering and symbolic analysis are kept)
  HessianAssembly hessian_;          // Newton: the Hessian's fixed pattern
  int factorizations_ = 0;
  double factor_seconds_ = 0.0;
  std::string setup_problem_;
};

// Newton's Hessian of g at x over the unknowns (3 n_u × 3 n_u, stacked x, y, z
// per unknown): M/Δt² plus each spring's 3×3 block
//     k [n nᵀ + max(0, 1 − L/l)(I − n nᵀ)],   n = (x_i − x_j)/l,
// the true block with its negative eigenvalue (1 − L/l < 0 when compressed)
// clamped to 0; with clamp = false the true block k [n nᵀ + (1 − L/l)(I − n nᵀ)].
// Coincident ends use n = (1, 0, 0) as local_step does (and clamp there).
SparseMatrix newton_hessian(const Problem& problem, const Eigen::Matrix3Xd& x, bool clamp = true);
// ∇g at x over the unknowns, stacked like the Hessian.
Eigen::VectorXd newton_gradient(const Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y);

// ------------------------------------------------------------------ a run

struct StepRecord {
  int step = 0;              // 0: the initial state
  double time = 0.0;         // s
  StepReport report;         // step 0: empty
  StrainStats strain;        // strain error over the springs (common/metrics.h)
  double kinetic = 0.0;      // J
  double potential = 0.0;    // gravity, J, zero at the origin
  double elastic = 0.0;      // spring_energy, J
  std::string problem;       // empty when healthy (see run_steps)
};
using StepCallback = std::function<void(const StepRecord&, const Particles&)>;

struct RunResult {
  int steps_done = 0;
  long long iterations_done = 0;  // over all steps
  double objective = 0.0;         // the last step's final objective, J
  int failed_decreases = 0;       // over all steps (Newton)
  double energy_start = 0.0;      // kinetic + potential + elastic, J
  double energy_end = 0.0;
  double energy_scale = 0.0;      // J (common/health.h), plus the initial elastic energy
  double seconds = 0.0;           // wall time of all steps
  std::string problem;            // empty unless the run stopped unhealthy
  int problem_step = -1;
};

// Runs `steps` steps in common/frame_loop.h's loop, measuring after each and
// calling on_step for step 0 and every step after it. Stops at the first step
// that reports a problem, or whose state is unhealthy (common/health.h:
// non-finite, strain >= 1e3), or whose total energy rose more than
// energy_scale above its start. `output` asks the loop for the per-step CSV
// (index "step", step_columns()).
RunResult run_steps(Particles& particles, Solver& solver, const StepSettings& settings, int steps,
                    const StepCallback& on_step = nullptr, const FrameOutput& output = {});

// The lab's columns of the per-step CSV: objective (J), iterations, converged
// (1/0), failed_decreases, seconds (the solver's), max_strain, rms_strain,
// kinetic, potential, elastic, total_energy (J).
std::vector<std::string> step_columns();

}  // namespace cl::lab06
