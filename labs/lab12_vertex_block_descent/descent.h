#pragma once
// Lab 12 — given code: the implicit-Euler step by vertex block descent (your
// four functions of vbd.h, K sweeps), with the initial guesses of Chen et al.
// (2024: plain inertia y, or the paper's adaptive one) and, optionally, the
// Chebyshev acceleration of lab 11 (Wang 2015; Chen et al. §3.8) applied
// after each sweep by lab 11's accelerated loop (accelerated.h); and the loop
// over a scene's steps on common/frame_loop.h.
// It owns the state; the functions of vbd.h stay stateless.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../lab06_projective_dynamics/simulation.h"
#include "accelerated.h"
#include "common/csv.h"
#include "common/frame_loop.h"
#include "common/particles.h"
#include "common/scene.h"
#include "vbd.h"

namespace cl::lab12 {

enum class Method { kVbd, kVbdChebyshev };
const char* method_name(Method method);  // "vbd" or "vbd-chebyshev"
// Throws std::invalid_argument for a name that is neither.
Method method_from_name(const std::string& name);

// The first iterate x⁰ of a step (README.md, "The initial guess").
enum class Init { kInertia, kAdaptive };
const char* init_name(Init init);  // "inertia" or "adaptive"
Init init_from_name(const std::string& name);  // throws std::invalid_argument

struct Settings {
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;     // K: sweeps, >= 0
  double tolerance = 0.0;  // stop once (g_prev − g)/g_prev < tolerance (lab 06's rule; 0: all K)
  Init init = Init::kAdaptive;
  double rho = 0.0;        // Chebyshev: the spectral radius, [0, 1) (0: plain sweeps)
};

// The adaptive initial guess (Chen et al. 2024; as the authors' TinyVBD), per movable particle:
//     x⁰ = x + Δt v + Δt² ã ĝ,   ĝ = g/‖g‖,   ã = clamp(a · ĝ, 0, ‖g‖),
// a = (v − v_previous)/Δt the acceleration of the previous step. Without a
// previous step (has_previous false), or for ‖g‖ = 0, it is y (predict).
// Pinned particles stay where they are.
Eigen::Matrix3Xd adaptive_guess(const Particles& particles, const Eigen::Matrix3Xd& previous_velocity,
                                bool has_previous, const Eigen::Vector3d& gravity, double dt);

struct IterationRecord {
  int iteration = 0;        // 0: the initial guess
  double objective = 0.0;   // g(x^k), J
  double omega = 1.0;       // Chebyshev's weight (1: a plain sweep)
  bool restarted = false;   // the accelerated iterate was rejected (lab 11's rule)
  double seconds = 0.0;     // wall time of the method's own work since the step began
};
using IterationCallback = std::function<bool(const IterationRecord&)>;  // true: end the step here

struct StepReport {
  int iterations_done = 0;
  double objective = 0.0;   // g at the result, J
  int restarts = 0;
  bool converged = false;   // stopped by the tolerance
  double seconds = 0.0;
  std::string problem;      // non-empty: the step failed; the particles are unchanged
};

// One scene's solver: lab 06's Problem, the adjacency, the colouring (once).
class Solver {
 public:
  // Throws what lab06::make_problem throws.
  Solver(const Eigen::VectorXd& inv_mass, const std::vector<Spring>& springs, double dt);

  // One step: y = lab06::predict, x⁰ (settings.init), K sweeps, then
  // v ← (x^K − x)/Δt (0 for pinned particles), x ← x^K. Remembers v for the
  // next step's adaptive guess. Throws std::invalid_argument for settings out of range.
  StepReport step(Particles& particles, Method method, const Settings& settings,
                  const IterationCallback& on_iteration = nullptr);

  // The sweeps without the step around them: x (3 × n, pinned columns = y)
  // towards the minimiser of g for the prediction y.
  StepReport minimise(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, Method method, const Settings& settings,
                      const IterationCallback& on_iteration = nullptr) const;

  // ρ of plain VBD measured on one step from `start` (not changed), as lab 11
  // measures PD's: the update lengths of up to `iterations` sweeps from y,
  // given to lab11::estimate_spectral_radius.
  double estimate_rho(const Particles& start, const Settings& settings, int iterations = 400) const;

  void forget_history() { has_previous_ = false; }  // the next adaptive guess is y
  const lab06::Problem& problem() const { return problem_; }
  const Adjacency& adjacency() const { return adjacency_; }
  const std::vector<int>& colours() const { return colours_; }
  int colour_count() const;  // colours of the whole colouring (pinned particles included)
  const std::vector<std::vector<int>>& groups() const { return groups_; }

 private:
  lab11::PlainIteration sweep(const Eigen::Matrix3Xd& y) const;  // one vbd_sweep for the prediction y

  lab06::Problem problem_;
  Adjacency adjacency_;
  std::vector<int> colours_;
  std::vector<std::vector<int>> groups_;
  Eigen::Matrix3Xd previous_velocity_;
  bool has_previous_ = false;
};

// ------------------------------------------------------------------ a run

struct StepRecord {
  int step = 0;
  StepReport report;
  StrainStats strain;
  double total_energy = 0.0;  // kinetic + gravity + springs, J
  std::string problem;
};
using StepCallback = std::function<void(const StepRecord&, const Particles&)>;
using RunIterationCallback = std::function<void(int step, const IterationRecord&)>;

struct RunResult {
  int steps_done = 0;
  long long iterations_done = 0;
  int restarts = 0;
  double seconds = 0.0;
  double energy_start = 0.0, energy_end = 0.0;
  std::string problem;
  int problem_step = -1;
};

// Runs `steps` steps in common/frame_loop.h's loop (health, the energy
// verdict with the scene's energy scale plus its initial elastic energy, the
// per-step CSV of step_columns() when output asks for it).
RunResult run_steps(Particles& particles, Solver& solver, Method method, const Settings& settings, int steps,
                    const StepCallback& on_step = nullptr, const RunIterationCallback& on_iteration = nullptr,
                    const FrameOutput& output = {});

// objective, iterations, converged, restarts, seconds, max_strain, rms_strain, total_energy.
std::vector<std::string> step_columns();

// ------------------------------------------------------------------ experiment 2

// One cell of the stability table (README.md, experiment 2): the scene with
// every spring at `stiffness` and the step `dt`, run for the scene's steps
// with K = `iterations` sweeps per step.
struct StabilityCell {
  double stiffness = 0.0;  // N/m
  double dt = 0.0;         // s
  int iterations = 0;
  RunResult result;
};

// The table's grid: k = 1e2, 1e4, …, 1e12 N/m; Δt = 1e-4, 1e-3, 1e-2, 0.1, 0.5 s; K = 1, 10, 100.
// Cells in the order k, then Δt, then K; gravity is the scene's, settings.rho 0 plain VBD.
std::vector<StabilityCell> stability_cells(const Scene& scene, Method method, const Settings& settings);

// The table as README.md shows it: a row per k, a column per Δt, each cell
// "a / b / c" for K = 1, 10, 100 with ✓ (every step healthy) or ✗n (stopped
// at step n), then one line per kind of stop with its count.
std::string stability_markdown(const std::vector<StabilityCell>& cells);

// stiffness, dt, iterations, steps_done, stopped_at_step (empty: none), problem.
CsvTable stability_csv(const std::vector<StabilityCell>& cells);

}  // namespace cl::lab12
