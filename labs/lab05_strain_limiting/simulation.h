#pragma once
// Lab 05 — given code: the mass-spring step with a strain limiter, and the run
// loop around it, shared by the driver and the graded tests. It owns the state;
// the limiters in strain_limiting.h stay stateless.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/frame_loop.h"
#include "common/health.h"
#include "common/particles.h"
#include "common/scene.h"
#include "strain_limiting.h"

namespace cl::lab05 {

enum class Limit { kNone, kSprings, kTrianglesArea, kTrianglesStretch };

// "none", "springs", "triangles-area", "triangles-stretch".
const char* limit_name(Limit limit);
// The inverse; throws std::invalid_argument for any other text.
Limit parse_limit(const std::string& name);
bool limits_triangles(Limit limit);

struct StepSettings {
  double dt = 1e-3;                          // s, finite and > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;                       // K Gauss-Seidel sweeps of the limiter, >= 0
  Limit limit = Limit::kSprings;
  double sigma_min = 0.9;                    // the band, 0 < sigma_min <= sigma_max
  double sigma_max = 1.1;
};

// What the step needs about a scene, built once per scene and limiter. Only
// what the limiter uses is kept: a spring or no limiter has no triangle data.
struct LimitedSystem {
  std::vector<Spring> springs;        // every one with finite stiffness and rest length > 0
  std::vector<Triangle> triangles;    // triangle limiters only, in file order
  std::vector<TriangleRest> rests;    // triangles-stretch only: one per triangle, from the loaded positions
};

// Checks the scene for this lab and keeps what `limit` needs. Throws
// cl::InputError, naming the scene file and the spring (springs[s] in the
// scene's order, generated ones included), for a spring of infinite stiffness
// (a hard constraint has no Hooke force) or of rest length 0 (σ = ℓ/L is
// undefined), and for a triangle limiter on a scene without triangles.
// Triangle rest shapes are the triangles' shapes at load (make_triangle_rest);
// the area limiter uses each Triangle's rest_area, which the loader computes
// before any "jitter" moves the particles. The shipped lab 05 scenes have no
// jitter, so the two rest shapes agree to round-off.
LimitedSystem make_limited_system(const Scene& scene, Limit limit);

// One step of size dt (README.md, "The step"):
//   1. every movable particle: v ← v + Δt (g + w f), f = Σ −k (‖x_i − x_j‖ − L) n
//      over the springs (n = (x_i − x_j)/‖x_i − x_j‖; coincident ends: no force);
//      x̃ ← x + Δt v. A pinned particle keeps x̃ = x and gets v = 0.
//   2. K sweeps of settings.limit over the springs (or triangles) in file order,
//      Gauss-Seidel, each correction applied at once: x̃ → x'.
//   3. v ← v + (x' − x̃)/Δt; x ← x'.
// Throws std::invalid_argument for dt not finite or ≤ 0, iterations < 0, or
// particles not sized alike; the limiters throw for a bad band.
void limited_step(Particles& particles, const LimitedSystem& system, const StepSettings& settings);

// How far outside the band a spring-limited run's strain may go: 0.5/K. K
// Gauss-Seidel sweeps leave a residual that falls like 1/K (README.md, "How
// close K sweeps get"); on the shipped curtains at their Δt it stays below
// 0.4/K for bands from ±1 % to ±10 %. Infinite for K = 0.
double band_tolerance(int iterations);

// Signed strain ℓ/L − 1 over the springs: the largest (stretch) and the
// smallest (compression). A NaN stays visible in both. 0 and 0 without springs.
struct SignedStrain {
  double max = 0.0;
  double min = 0.0;
};
SignedStrain signed_strain(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// Σ ½ k (‖x_i − x_j‖ − L)² over the springs, J.
double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// Σ ½ k (L · max(σ_max − 1, 1 − σ_min))² over the springs, J: the most elastic
// energy the springs hold with every one of them inside the band [σ_min, σ_max].
double band_energy(const std::vector<Spring>& springs, double sigma_min, double sigma_max);

// What one step looked like after it was taken (step 0: the initial state).
struct StepRecord {
  int step = 0;
  double time = 0.0;          // s
  SignedStrain strain;        // ℓ/L − 1
  double rms_strain_error = 0.0;  // RMS of |ℓ − L| / L
  double kinetic = 0.0;       // J
  double potential = 0.0;     // J, gravity, zero at the origin
  double elastic = 0.0;       // J
  double seconds = 0.0;       // wall time of this step
  std::string problem;        // empty when healthy
};

struct RunResult {
  int steps_done = 0;
  double max_strain = 0.0;        // max over the steps taken (1 … steps_done) of SignedStrain::max
  int max_strain_step = 0;        // the step where it was reached (0: no step taken)
  double min_strain = 0.0;        // min over the steps taken of SignedStrain::min
  int min_strain_step = 0;
  double energy_start = 0.0;      // kinetic + potential + elastic, J
  double energy_end = 0.0;
  double max_energy_rise = 0.0;   // max over steps of E(t) − E(0), J (>= 0)
  double energy_scale = 0.0;      // common/health.h energy_scale, J
  // What the scene can release inside the band, J: energy_scale (falling its
  // own size) plus band_energy (every spring let go from the band's far edge).
  // Equal to energy_scale without a limiter.
  double energy_bound = 0.0;
  double seconds = 0.0;           // wall time of all steps
  std::string problem;            // empty unless the run became unstable (it stops there)
  int problem_step = -1;
  // A run without the energy check (check_energy false) whose total energy
  // still rose more than energy_scale above its start: the first such step
  // (-1: none) and common/health.h's energy_rise_problem line for it. The run
  // went on; energy_contained says whether the limiter held it ("Bounded only
  // by the limiter", README.md).
  int energy_exceeded_step = -1;
  std::string energy_exceeded;
};

// True when a limited run whose total energy rose above energy_scale
// (energy_exceeded_step >= 0) was still held by its limiter: it did not stop,
// `band_held` (a spring-limited run inside the band ± band_tolerance(K)
// throughout; pass true for the triangle limiters, which bound triangles, not
// springs), and its largest rise stayed within energy_bound. A run whose
// energy never rose above the scale has nothing to contain: false.
bool energy_contained(const RunResult& result, bool band_held);

using StepCallback = std::function<void(const StepRecord&, const Particles&)>;

// Runs `steps` steps in common/frame_loop.h's loop, measuring after each and
// calling `on_step` (if set) for step 0 and every step after it. Stops at the
// first unhealthy step and says why in RunResult::problem: common/health.h's
// health_problem (a non-finite value, or a strain error >= kUnstableStrain), a
// non-finite energy, or — with check_energy — a total energy (kinetic +
// gravity + elastic) more than energy_scale above its start. A limited step
// can hold a stiff cloth inside the band while its springs store far more than
// that (README.md, "Bounded only by the limiter"), so the driver checks energy
// for unlimited runs only; without the check, a rise above the scale does not
// stop the run but is reported in RunResult::energy_exceeded_step. `output`
// asks the loop for the per-step CSV (index "step", step_columns(), status
// "unstable: …").
RunResult run_steps(Particles& particles, const LimitedSystem& system, const StepSettings& settings, int steps,
                    bool check_energy, const StepCallback& on_step = nullptr, const FrameOutput& output = {});

// The lab's columns of the per-step CSV: max_strain, min_strain (ℓ/L − 1),
// rms_strain_error, kinetic, potential, elastic, total_energy (J), seconds.
std::vector<std::string> step_columns();

}  // namespace cl::lab05
