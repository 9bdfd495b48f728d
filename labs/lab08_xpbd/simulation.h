#pragma once
// Lab 08 — given code: the frame loop around xpbd_step (or lab 04's pbd_step),
// shared by the driver and the graded tests. It owns the state, the
// multipliers included; xpbd_step stays stateless.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "pbd.h"
#include "xpbd.h"

namespace cl::lab08 {

enum class Method { kPbd, kXpbd };

// A frame of length dt done as `substeps` steps of dt / substeps, each with
// `iterations` Gauss-Seidel sweeps: lab 04's pbd_step (every spring hard, its
// stiffness unused) or xpbd_step (each spring's compliance 1/k).
struct FrameSettings {
  Method method = Method::kXpbd;
  double dt = 1.0 / 60.0;                    // frame, s
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;
  int substeps = 1;
};

// One frame. `lambda` gets the last substep's multipliers (xpbd: one per
// spring, N·s² of the substep; pbd: emptied, lab 04 keeps none). Throws
// std::invalid_argument for substeps < 1 (and whatever the step throws).
void advance_frame(Particles& particles, const lab04::ConstraintSet& constraints, const FrameSettings& frame,
                   Eigen::VectorXd& lambda);

// Σ over springs of finite stiffness of ½ k (‖x_i − x_j‖ − L)², J. Hard
// constraints store no energy.
double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// Σ over springs of (‖x_i − x_j‖ − L), m: for a chain, how much longer it is
// than its rest length.
double total_stretch(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// The static total stretch of a chain hanging under `gravity` from its pinned
// first particle: spring s joins particles s and s+1 and carries the weight
// of everything below it, so it stretches by |g| Σ_{p > s} m_p / k_s, and the
// chain by the sum of those (for N equal beads of mass m and equal k:
// m|g| N(N+1) / (2k)). Empty when the scene is not such a chain: springs
// other than (s, s+1) in order, a pinned particle other than the first, or a
// hard spring.
std::optional<double> hanging_chain_stretch(const Particles& particles, const std::vector<Spring>& springs,
                                            const Eigen::Vector3d& gravity);

// What one frame looked like after it was computed (frame 0: the initial state).
struct FrameRecord {
  int frame = 0;
  double time = 0.0;        // s
  StrainStats strain;       // over the scene's springs
  double total_stretch = 0.0;  // m
  double kinetic = 0.0;     // J
  double potential = 0.0;   // J, gravity, zero at the origin
  double elastic = 0.0;     // J, finite-stiffness springs; 0 for pbd (its springs are hard)
  double seconds = 0.0;     // wall time of this frame's steps
  std::string problem;      // empty when healthy
};

struct RunPlan {
  int frames = 0;             // frames to run; the most, when settling
  int window_frames = 60;     // frames per averaging window
  // > 0: stop after the first window at which the mean total stretch of the
  // last three windows agree to this relative spread, (max − min) <= tol · |last|
  // (common/window_means.h).
  double settle_tolerance = 0.0;
};

struct RunResult {
  int frames_done = 0;
  int windows_done = 0;
  double window_total_stretch = 0.0;  // last complete window: mean total stretch, m
  double window_max_strain = 0.0;     // last complete window: mean max strain
  double window_spread = -1.0;        // (max − min)/|last| of the last three window means (-1: < 3)
  bool settled = false;
  double energy_start = 0.0;          // kinetic + potential + elastic (xpbd only), J
  double energy_end = 0.0;
  double max_energy_rise = 0.0;       // max over frames of E(t) − E(0), J (>= 0)
  double energy_scale = 0.0;          // common/health.h's, J
  double seconds = 0.0;               // wall time of all steps
  Eigen::VectorXd lambda;             // the last substep's multipliers (N·s²; empty for pbd)
  std::string problem;                // empty unless the run diverged (it stops there)
  int problem_frame = -1;
};

using FrameCallback = std::function<void(const FrameRecord&, const Particles&)>;

// Runs frame by frame in common/frame_loop.h's loop, measuring after each and
// calling `on_frame` (if set) for frame 0 and every frame after it. Stops at
// the first unhealthy frame (health_problem, or a kinetic + gravitational
// energy that rose more than energy_scale above its start — lab 04's check;
// the elastic energy is left out because an unconverged XPBD step
// over-stretches the springs, see simulation.cpp) and says why in
// RunResult::problem. `output` asks the loop for the per-frame CSV
// (frame_columns()) and OBJ frames.
RunResult run_frames(Particles& particles, const lab04::ConstraintSet& constraints, const FrameSettings& frame,
                     const RunPlan& plan, const FrameCallback& on_frame = nullptr, const FrameOutput& output = {});

// The lab's columns of the per-frame CSV: max_strain, rms_strain,
// total_stretch (m), kinetic, potential, elastic, total_energy (J), seconds.
std::vector<std::string> frame_columns();

}  // namespace cl::lab08
