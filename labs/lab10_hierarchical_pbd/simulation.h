#pragma once
// Lab 10 — given code: the PBD step around solve_hierarchy, the frame loop, and
// the convergence measurement of experiment 1. Shared by the driver and the
// graded tests; solve_hierarchy stays stateless.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/health.h"
#include "common/hierarchy.h"
#include "common/metrics.h"
#include "common/particles.h"
#include "hpbd.h"

namespace cl::lab10 {

struct HpbdSettings {
  double dt = 1.0 / 60.0;                    // s, > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  std::vector<int> iterations;               // sweeps per level, levels[0] (the cloth) first
};

// Projections one coarse-to-fine pass makes: Σ_l iterations[l] · (springs on level l).
long long projections_per_pass(const ClothHierarchy& hierarchy, const std::vector<int>& iterations);

// Lab 04's step with the hierarchical projection: for movable particles
// v ← v + Δt g, p ← x + Δt v (pinned: p = x); solve_hierarchy(p); v ← (p − x)/Δt,
// x ← p. With one level it is lab 04's Gauss-Seidel pbd_step. Throws
// std::invalid_argument for dt not finite or ≤ 0 (and whatever solve_hierarchy throws).
void hpbd_step(Particles& particles, const ClothHierarchy& hierarchy, const HpbdSettings& settings);

// What one frame looked like after it was computed (frame 0: the initial state).
struct FrameRecord {
  int frame = 0;
  double time = 0.0;       // s
  StrainStats strain;      // over the cloth's own springs (level 0)
  double kinetic = 0.0;    // J
  double potential = 0.0;  // J, zero at the origin
  double seconds = 0.0;    // wall time of this frame's step
  std::string problem;     // empty when healthy
};

struct RunResult {
  int frames_done = 0;
  double energy_start = 0.0;  // kinetic + potential, J
  double energy_end = 0.0;
  double seconds = 0.0;       // wall time of all steps
  long long projections = 0;  // constraint projections of all steps
  std::string problem;        // empty unless the run became unstable (it stops there)
  int problem_frame = -1;
};

using FrameCallback = std::function<void(const FrameRecord&, const Particles&)>;

// `frames` steps of hpbd_step, measured after each and passed to `on_frame`
// (frame 0 too). Stops at the first unhealthy frame: health_problem
// (common/health.h), or a total energy more than energy_scale above its start.
RunResult run_frames(Particles& particles, const ClothHierarchy& hierarchy, const HpbdSettings& settings,
                     int frames, const FrameCallback& on_frame = nullptr);

// Experiment 1: how fast one step's projection converges. From `particles`
// (normally a cloth at rest) predict one step (gravity; pinned particles stay),
// then repeat coarse-to-fine passes with `iterations` sweeps per level (the
// cloth first) and measure the cloth's max strain after every sweep on the
// cloth, until every target is reached or `max_sweeps` cloth sweeps are done.
// A pass is solve_hierarchy with the cloth's count set to 0 (the coarse levels
// and the prolongations), then iterations[0] sweeps of lab02 on the cloth, one
// at a time — the same as solve_hierarchy with `iterations`, measured inside.
// With one level this is plain Gauss-Seidel, measured after every sweep.
struct ConvergenceSample {
  int passes = 0;              // coarse-to-fine passes begun
  int sweeps = 0;              // sweeps on the cloth so far
  long long projections = 0;   // all projections so far, coarse ones included
  double seconds = 0.0;        // solver wall time so far (the strain measurements excluded)
  StrainStats strain;          // the cloth's
};
struct TargetReached {
  double target = 0.0;         // max strain
  bool reached = false;
  ConvergenceSample at;        // the first sample at or below the target (valid when reached)
};
struct ConvergenceResult {
  std::vector<ConvergenceSample> samples;  // the prediction (all zero counts), then one per cloth sweep
  std::vector<TargetReached> targets;      // in the order given
};
// Throws std::invalid_argument for dt not finite or ≤ 0, iterations not one
// per level, a negative count, iterations[0] < 1 or max_sweeps < 0.
ConvergenceResult converge_one_step(const Particles& particles, const ClothHierarchy& hierarchy, double dt,
                                    const Eigen::Vector3d& gravity, const std::vector<int>& iterations,
                                    const std::vector<double>& targets, int max_sweeps);

}  // namespace cl::lab10
